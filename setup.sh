#!/usr/bin/env bash
# Installs what cam_fmu needs on a fresh Debian machine (run as root).
# Idempotent: re-running it changes nothing once everything is in place.
set -euo pipefail
cd "$(dirname "$0")"

# Debian packages, installed only when missing (apt is not touched otherwise):
# - gcc:      compiles the C engine library Python calls and the x86_64 test hosts; its binutils (readelf,
#             objdump) read the other platforms' binaries in the tests. Every FMU's binaries for every
#             platform come from zig (the ziglang wheel, pyproject.toml's build extra), not from apt;
# - valgrind: the memcheck tests of the binary (tests/test_native_*.py);
# - libtbb12: needed by the FMU host `ecos`;
# - wine64:   runs the x86_64-windows binaries in the Windows test hosts (tests/hosts/test_engine_fmu_win64.py);
# - qemu-user-static, libc6-arm64-cross: run the aarch64-linux binaries in an aarch64 test host
#             (qemu-aarch64-static -L /usr/aarch64-linux-gnu; tests/hosts/test_fmu_platforms.py).
# - clang:    the second C compiler every C file must compile under warning-free (tests/hosts/test_c_compilers.py).
missing=()
for pkg in gcc clang valgrind libtbb12 wine64 qemu-user-static libc6-arm64-cross; do
    if ! dpkg-query -W -f='${Status}' "$pkg" 2>/dev/null | grep -q "install ok installed"; then
        missing+=("$pkg")
    fi
done
if [ "${#missing[@]}" -gt 0 ]; then
    apt-get update
    DEBIAN_FRONTEND=noninteractive apt-get install -y "${missing[@]}"
fi

# the test environment pinned (constraints/test.txt; refresh: bash constraints/refresh.sh), the package keeps ranges
python -m pip install -c constraints/test.txt -e ".[test]"
# the C engine's shared library (the system C compiler; skipped while current: its name hashes its sources)
python -m cam_fmu.engine.build
