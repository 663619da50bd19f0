"""The `cam-fmu` command line: one module per subcommand, registered in SUBCOMMANDS.

Each subcommand module defines

    add_parser(subparsers) -> argparse.ArgumentParser   # subparsers.add_parser(...)
    run(args) -> int                                    # exit status

and keeps its top-level imports light (numpy at most): every module is
imported to build `--help`; heavy imports (matplotlib, scipy, fmpy) belong
inside run().  To add a subcommand, write such a module and add its name here.
"""

from __future__ import annotations

import argparse
import importlib
import os
import sys
from typing import Sequence

SUBCOMMANDS: tuple[str, ...] = (
    "curve",      # characteristic values and plots of a motion law
    "contour",    # disc cam geometry, design checks, CSV/DXF export
    "simulate",   # run a scene: CSV + figure
    "bench",      # speed-accuracy benchmark of cam.fmu through fmpy
    "host_env",   # environment line for native FMU hosts (diagnostic)
)


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(
        prog="cam-fmu", description="Cam motion laws and an electromechanical cam drive FMU.")
    subparsers = parser.add_subparsers(dest="command", metavar="COMMAND", required=True)
    for name in SUBCOMMANDS:
        module = importlib.import_module(f"{__name__}.{name}")
        sub = module.add_parser(subparsers)
        sub.set_defaults(_run=module.run)
    return parser


FMU_SLAVE_MODULE = "camdrive_fmu_slave"  # imported into this process when cam.fmu is loaded here


def exit_after_fmu(status: int) -> int:
    """Leave at once (no interpreter teardown) when cam.fmu was loaded into this process.

    pythonfmu 0.7.0 can corrupt the heap when the interpreter tears down a
    process that has loaded a pythonfmu FMU: glibc then aborts with "corrupted
    double-linked list" after all the work is done (seen once in about 60 runs,
    under load). Output is flushed first; nothing is lost.
    """
    if FMU_SLAVE_MODULE in sys.modules:
        sys.stdout.flush()
        sys.stderr.flush()
        os._exit(status)
    return status


def main(argv: Sequence[str] | None = None) -> int:
    args = build_parser().parse_args(argv)
    return exit_after_fmu(args._run(args))


if __name__ == "__main__":
    sys.exit(main())
