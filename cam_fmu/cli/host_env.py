"""`cam-fmu host-env`: a diagnostic: the environment line of this machine's Python (LD_PRELOAD, PYTHONHOME,
PYTHONPATH). No host needs it for cam.fmu or pi_speed.fmu, which carry their own linux64 binary (docs/fmu.md)."""
from __future__ import annotations

import argparse
import json
import sys

def add_parser(subparsers) -> argparse.ArgumentParser:
    p = subparsers.add_parser(
        "host-env",
        help="a diagnostic: print this machine's Python environment line (no FMU host needs it)",
        description="Print LD_PRELOAD=... PYTHONHOME=... PYTHONPATH=... for this machine's Python: "
                    "prefix a native co-simulation host with it, e.g. "
                    "`env $(cam-fmu host-env) ecos simulate --path models/cam.fmu --stopTime 2 --stepSize 1e-3`.")
    fmt = p.add_mutually_exclusive_group()
    fmt.add_argument("--export", action="store_true", help="print `export VAR=...` lines for a shell script")
    fmt.add_argument("--json", action="store_true", help="print a JSON object")
    return p


def run(args) -> int:
    from ..tools.host_env import HostEnvError, env_line, host_env

    try:
        env = host_env()
    except HostEnvError as exc:
        print(f"cam-fmu host-env: error: {exc}", file=sys.stderr)
        return 1
    if args.json:
        print(json.dumps(env))
    else:
        print(env_line(env, export=args.export))
    return 0
