#!/usr/bin/env bash
# Installs what cam_fmu needs on a fresh Debian machine (run as root).
# Idempotent: re-running it changes nothing once everything is in place.
set -euo pipefail
cd "$(dirname "$0")"

# Debian packages, installed only when missing (apt is not touched otherwise):
# - gcc:      compiles the C engine and the FMI glue (every FMU's binary, the library Python calls)
#             and the test hosts;
# - valgrind: the memcheck tests of the binary (tests/test_native_*.py);
# - libtbb12: needed by the FMU host `ecos`;
# - gcc-mingw-w64-x86-64: cross-compiles cam.fmu's win64 binary (cam_fmu/fmu/engine_fmu.py);
# - wine64:   runs that binary in the win64 test host (tests/test_engine_fmu_win64.py).
missing=()
for pkg in gcc valgrind libtbb12 gcc-mingw-w64-x86-64 wine64; do
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
# the C engine's shared library (gcc; skipped while current: its name hashes its sources)
python -m cam_fmu.engine.build
