"""The `cam-fmu` command line: one module per subcommand, registered in SUBCOMMANDS.

Each subcommand module defines

    add_parser(subparsers) -> argparse.ArgumentParser   # subparsers.add_parser(...)
    run(args) -> int                                    # exit status

and keeps its top-level imports light (numpy at most): every module is
imported to build `cam-fmu --help` (a run imports its own only); heavy imports
(matplotlib, scipy, fmpy) belong inside run().  To add a subcommand, write such a module and add its name here.
"""

from __future__ import annotations

import argparse
import importlib
import os
import re
import sys
from typing import Sequence

SUBCOMMANDS: tuple[str, ...] = (
    "curve",      # characteristic values and plots of a motion law
    "contour",    # disc cam geometry, design checks, CSV/DXF export
    "simulate",   # run a scene: CSV + figure
    "bench",      # speed-accuracy benchmark of cam.fmu through fmpy
    "host_env",   # deprecated: no shipped FMU needs Python on the host any more
    "cosim",      # run an SSP (the speed loop) on the project's co-simulation master
    "python_block",  # a block written in Python (pythonfmu) packed as an FMU
    "sweep",      # parameter sweeps of a scene on dask.distributed
    "reflect",    # the inertia and load torque the motor sees over one turn
    "bode",       # the frequency response from the motor voltage to the motor and cam speed
    "jump",       # the speed at which a spring-closed follower leaves the cam; the spring it needs
    "cross_check",  # the FMI Cross-Check folders of the shipped FMUs, validated by fmpy
    "residual",   # the follower train's residual vibration after a rise, against r, per law
    "optimize_law",  # the harmonic-trapezoid law shaped against the residual over a band of r
    "polydyne",   # the cam profile that cancels the train's vibration at one speed, as a motion table
)


# A negative number in any notation (-1, -.5, -1e-3, -2.5E+4) is an option's value, not an option: argparse's own
# test (before Python 3.13) knows no exponent, so `--amplitude -1e-3` was "expected one argument" instead of the
# command's own range check. No option of cam-fmu looks like a number.
NEGATIVE_NUMBER = re.compile(r"^-(\d+\.?\d*|\.\d+)([eE][-+]?\d+)?$")


def command_module(word: str) -> str | None:
    """The module of the subcommand ``word`` names on the command line (``cross-check`` -> ``cross_check``), or
    None when it names none."""
    name = word.replace("-", "_")
    return name if name in SUBCOMMANDS and word == name.replace("_", "-") else None


def build_parser(command: str | None = None) -> argparse.ArgumentParser:
    """The parser of every subcommand, or with ``command`` (a module of SUBCOMMANDS) of that one only: a run
    imports its own subcommand's module, not the eleven others (`cam-fmu --help` and a word that is no command
    still import them all, to list them)."""
    parser = argparse.ArgumentParser(
        prog="cam-fmu", description="Cam motion laws and an electromechanical cam drive FMU.")
    parser._negative_number_matcher = NEGATIVE_NUMBER  # type: ignore[attr-defined]
    subparsers = parser.add_subparsers(dest="command", metavar="COMMAND", required=True)
    for name in SUBCOMMANDS if command is None else (command,):
        module = importlib.import_module(f"{__name__}.{name}")
        sub = module.add_parser(subparsers)
        sub._negative_number_matcher = NEGATIVE_NUMBER  # type: ignore[attr-defined]
        sub.set_defaults(_run=module.run)
    return parser


# Imported into this process when a pythonfmu FMU (a block written in Python, `cosim --controller`) is loaded
# here or one is built: then leave with os._exit. The shipped FMUs host no Python (their binaries are C).
FMU_SLAVE_MODULES = ("pythonfmu",)


def exit_after_fmu(status: int) -> int:
    """Leave at once (no interpreter teardown) when a pythonfmu FMU was loaded into this process.

    pythonfmu 0.7.0 can corrupt the heap when the interpreter tears down a
    process that has loaded a pythonfmu FMU: glibc then aborts with "corrupted
    double-linked list" after all the work is done (seen once in about 60 runs,
    under load). Output is flushed first; nothing is lost.
    """
    if any(loaded.startswith(FMU_SLAVE_MODULES) for loaded in list(sys.modules)):
        sys.stdout.flush()
        sys.stderr.flush()
        os._exit(status)
    return status


class CliError(Exception):
    """A user error any subcommand may raise: reported as one line, exit 2."""


def _expected_errors() -> tuple[type[BaseException], ...]:
    """Exceptions that mean bad input (files, values, scenes, FMUs), never a bug: one line, exit 2."""
    errors: list[type[BaseException]] = [CliError, OSError, UnicodeDecodeError, ValueError]
    for module, name in (("..fmu.build", "FmuFileError"), ("..experiments.runner", "EngineError"),
                         ("..experiments.cosim", "CosimError"), ("..fmu.build", "BuildError")):
        try:
            errors.append(getattr(importlib.import_module(module, __name__), name))
        except ImportError:  # pragma: no cover - a module missing is itself a bug, reported below
            pass
    return tuple(errors)


def main(argv: Sequence[str] | None = None) -> int:
    argv = list(sys.argv[1:] if argv is None else argv)
    parser = build_parser(command_module(argv[0]) if argv else None)
    args = parser.parse_args(argv)
    try:
        status = args._run(args)
    except KeyboardInterrupt:
        print(f"cam-fmu {args.command}: interrupted", file=sys.stderr)
        status = 130
    except _expected_errors() as exc:
        status = report_error(args.command, exc)
    except Exception as exc:  # noqa: BLE001 - FMU and engine failures (fmpy's FMICallException...)
        if type(exc).__module__.split(".")[0] in ("fmpy", "cam_fmu", "zipfile", "xml", "tomllib"):
            status = report_error(args.command, exc)
        else:
            raise
    return exit_after_fmu(status)


def report_error(command: str, exc: BaseException) -> int:
    """``cam-fmu CMD: error: <one line>`` on stderr; exit status 2."""
    text = str(exc).strip() or type(exc).__name__
    if isinstance(exc, UnicodeDecodeError):
        text = f"not a text file (cannot decode byte 0x{exc.object[exc.start]:02x} at position {exc.start})"
    elif isinstance(exc, OSError) and exc.filename is not None:
        text = f"{exc.strerror or exc}: {exc.filename}"
    line = " ".join(text.split())
    print(f"cam-fmu {command.replace('_', '-')}: error: {line}", file=sys.stderr)
    return 2


if __name__ == "__main__":
    sys.exit(main())
