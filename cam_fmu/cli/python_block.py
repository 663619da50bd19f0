"""`cam-fmu python-block [SCRIPT] --dest FILE.fmu`: a block written in Python (a pythonfmu slave script,
default the shipped PI controller example) packed as an FMU, to run in `cam-fmu cosim --controller`."""
from __future__ import annotations

import argparse
from pathlib import Path


def add_parser(subparsers) -> argparse.ArgumentParser:
    p = subparsers.add_parser(
        "python-block", help="pack a block written in Python (pythonfmu) as an FMU",
        description="Pack a pythonfmu slave script (default: the shipped example, a PI speed controller) into an "
                    "FMI 2.0 co-simulation FMU. The FMU embeds CPython: the machine that runs it needs the same "
                    "Python minor version (docs/fmu.md, 'Blocks written in Python').")
    p.add_argument("script", metavar="SCRIPT", nargs="?", default=None,
                   help="the slave script (default: cam_fmu/fmu/examples/python_pi_slave.py)")
    p.add_argument("--dest", metavar="FILE.fmu", default="out/python_pi.fmu", help="the FMU (default: out/python_pi.fmu)")
    return p


def run(args) -> int:
    from ..fmu import python_block

    try:
        path = python_block.build(Path(args.dest), Path(args.script) if args.script else python_block.EXAMPLE)
    except python_block.PythonBlockError as exc:
        raise ValueError(str(exc)) from None
    print(path)
    return 0
