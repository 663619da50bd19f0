#!/usr/bin/env bash
# Installs what cam_fmu needs on a fresh Debian 12 or Ubuntu 24.04 machine (run as root) into a virtual
# environment, .venv at the repository root: afterwards .venv/bin/python, .venv/bin/cam-fmu (README.md).
# Idempotent: re-running it changes nothing once everything is in place.
set -euo pipefail
cd "$(dirname "$0")"

say() { echo "setup.sh: $*"; }
die() { echo "setup.sh: error: $*" >&2; exit 1; }

# Debian packages, installed only when missing (apt is not touched otherwise):
# - gcc:      compiles the C engine library Python calls and the x86_64 test hosts; its binutils (readelf,
#             objdump) read the other platforms' binaries in the tests. Every FMU's binaries for every
#             platform come from zig (the ziglang wheel, pyproject.toml's build extra), not from apt;
# - valgrind: the memcheck tests of the binary (tests/test_native_*.py);
# - libtbb12: needed by the FMU host `ecos`;
# - wine64:   runs the x86_64-windows binaries in the Windows test hosts (tests/hosts/test_engine_fmu_win64.py);
# - qemu-user-static, libc6-arm64-cross: run the aarch64-linux binaries in an aarch64 test host
#             (qemu-aarch64-static -L /usr/aarch64-linux-gnu; tests/hosts/test_fmu_platforms.py);
# - clang:    the second C compiler every C file must compile under warning-free (tests/hosts/test_c_compilers.py);
# - python3, python3-venv: only when there is no python3 on PATH, or when `python3 -m venv` cannot work
#             (Debian's and Ubuntu's python3 leave venv's pip bootstrap to python3-venv).
apt_install() {
    [ "$#" -gt 0 ] || return 0
    local sudo=()
    if [ "$(id -u)" -ne 0 ]; then
        command -v sudo >/dev/null || die "missing Debian packages ($*): run setup.sh as root or install them"
        sudo=(sudo)
    fi
    say "installing with apt: $*"
    "${sudo[@]}" apt-get update
    DEBIAN_FRONTEND=noninteractive "${sudo[@]}" apt-get install -y "$@"
}
installed() { dpkg-query -W -f='${Status}' "$1" 2>/dev/null | grep -q "install ok installed"; }

missing=()
for pkg in gcc clang valgrind libtbb12 wine64 qemu-user-static libc6-arm64-cross; do
    installed "$pkg" || missing+=("$pkg")
done
command -v python3 >/dev/null || missing+=(python3 python3-venv)
apt_install "${missing[@]}"

# The Python that makes the environment: python3 from PATH, at least 3.10 (pyproject.toml's requires-python).
PYTHON=$(command -v python3) || die "no python3 on PATH"
"$PYTHON" -c 'import sys; sys.exit(sys.version_info < (3, 10))' ||
    die "$PYTHON is $("$PYTHON" --version 2>&1): cam_fmu needs Python 3.10 or newer; put one first on PATH as python3"

VENV=.venv
venv_works() { [ -x "$VENV/bin/python" ] && "$VENV/bin/python" -m pip --version >/dev/null 2>&1 &&
               "$VENV/bin/python" -c 'import sys; sys.exit(sys.version_info < (3, 10))'; }
if ! venv_works; then
    rm -rf "$VENV"  # a half-made one (no pip) or one of an older Python
    if ! "$PYTHON" -m venv "$VENV"; then
        rm -rf "$VENV"
        apt_install python3-venv  # Debian/Ubuntu: venv's pip bootstrap (ensurepip) comes with it
        "$PYTHON" -m venv "$VENV" || die "$PYTHON -m venv $VENV failed even with python3-venv installed"
    fi
    say "made the virtual environment $VENV ($("$VENV/bin/python" --version))"
fi

# the test environment pinned (constraints/test.txt; refresh: bash constraints/refresh.sh), the package keeps
# ranges; skipped while the environment holds what these files ask for (the stamp: their hash)
stamp=$(cat pyproject.toml setup.py constraints/test.txt | "$VENV/bin/python" -c \
        'import hashlib, sys; print(hashlib.sha256(sys.stdin.buffer.read()).hexdigest())')
if [ "$(cat "$VENV/.cam_fmu_installed" 2>/dev/null)" != "$stamp" ] ||
   ! "$VENV/bin/python" -I -c 'import sys, cam_fmu; sys.exit(not cam_fmu.__file__.startswith(sys.argv[1]))' \
       "$PWD/" 2>/dev/null; then
    "$VENV/bin/python" -m pip install -c constraints/test.txt -e ".[test]"
    echo "$stamp" > "$VENV/.cam_fmu_installed"
fi
# the C engine's shared library (the system C compiler; skipped while current: its name hashes its sources)
"$VENV/bin/python" -m cam_fmu.engine.build
