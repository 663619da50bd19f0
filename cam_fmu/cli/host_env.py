"""`cam-fmu host-env`: deprecated. It printed the environment a native host needed for the former
Python-hosting pi_speed.fmu; every FMU the project ships is C now and needs no Python on the host."""
from __future__ import annotations

import argparse
import sys


def add_parser(subparsers) -> argparse.ArgumentParser:
    return subparsers.add_parser(
        "host-env", help="deprecated: no shipped FMU needs Python on the host",
        description="Deprecated: cam.fmu, cam3.fmu and pi_speed.fmu are C and need no Python, LD_PRELOAD, "
                    "PYTHONHOME or PYTHONPATH on the machine that runs them. A block you write in Python "
                    "(cam-fmu python-block) needs its own Python: docs/fmu.md, 'Blocks written in Python'.")


def run(args) -> int:
    print("cam-fmu host-env: deprecated: the shipped FMUs (cam.fmu, cam3.fmu, pi_speed.fmu) are C and need no "
          "Python on the host; nothing to set", file=sys.stderr)
    return 0
