#!/usr/bin/env bash
# Installs what cam_fmu needs on a fresh Debian machine (run as root).
# Idempotent: re-running it changes nothing once everything is in place.
set -euo pipefail
cd "$(dirname "$0")"

# libtbb12: needed by the FMU host `ecos`. Only touch apt when it is missing.
if ! dpkg-query -W -f='${Status}' libtbb12 2>/dev/null | grep -q "install ok installed"; then
    apt-get update
    apt-get install -y libtbb12
fi

python -m pip install -e ".[test]"
