"""Build the project's models: cam.fmu, pi_speed.fmu (FMI 2.0 co-simulation) and speed_loop.ssp.

    python build_fmu.py                          # -> models/cam.fmu, pi_speed.fmu, speed_loop.ssp, compliant_loop.ssp
    python -m cam_fmu.fmu.build --dest /tmp/x/cam.fmu
    python -m cam_fmu.fmu.build --model pi_speed --dest /tmp/x/pi_speed.fmu

- cam.fmu: the C engine compiled into a binary FMU that needs nothing but the C
  library (``engine_fmu``; docs/fmu.md).
- pi_speed.fmu: a controller written in Python, packed by pythonfmu with the
  project's Python-hosting binary (``python_fmu``).
- speed_loop.ssp: the two closing a speed loop (``experiments.ssp``).
"""
from __future__ import annotations

import argparse
import sys
from pathlib import Path
from typing import List, Sequence

from ..engine import targets
from . import binaries, engine_fmu, python_fmu

PACKAGE_DIR = Path(__file__).resolve().parents[1]  # this cam_fmu
ENGINE_MODELS = {"cam": 2, "cam3": 3}  # the C engine's FMUs and their FMI versions
MODELS = (*ENGINE_MODELS, *python_fmu.MODELS)  # every FMU the project builds
SSP_NAME = "speed_loop"  # models/speed_loop.ssp: pi_speed.fmu closing a speed loop around cam.fmu
SSP_NAMES = (SSP_NAME, "compliant_loop")  # and the loop on the cam's speed around a compliant shaft


class BuildError(RuntimeError):
    """A model could not be built; the message says why."""


def sources(model: str = "cam") -> list[Path]:
    """Every file whose content ends up in (or shapes) the FMU of ``model``."""
    if model in ENGINE_MODELS:
        return engine_fmu.sources()
    return python_fmu.sources(model=model)


def is_stale(fmu: Path, model: str = "cam") -> bool:
    """True when ``fmu`` is missing or older than one of its sources."""
    fmu = Path(fmu)
    if not fmu.is_file():
        return True
    newest = max(p.stat().st_mtime for p in sources(model) if p.is_file())
    return fmu.stat().st_mtime < newest


def build(dest: Path, model: str = "cam", verbose: bool = False, package_dir: Path | None = None,
          platforms: Sequence[str] | None = None) -> Path:
    """Build the FMU of ``model`` (one of MODELS) at ``dest`` (a path ending in .fmu) and return it.
    ``package_dir``: a Python FMU's bundle from another copy of the package (developers' tests).
    ``platforms``: a C model's targets (engine/targets.py; default all, ``["host"]``: this machine only)."""
    if model not in MODELS:
        raise BuildError(f"model {model!r}: allowed {', '.join(map(repr, MODELS))}")
    try:
        if model in ENGINE_MODELS:
            return engine_fmu.build(dest, fmi_version=ENGINE_MODELS[model], platforms=platforms)
        return python_fmu.build(dest, model, package_dir=package_dir, verbose=verbose)
    except (engine_fmu.FmuBuildError, python_fmu.BuildError, targets.TargetError) as exc:
        raise BuildError(str(exc)) from None


def build_ssp(dest: Path, cam: Path, pi_speed: Path, name: str = SSP_NAME) -> Path:
    """models/<name>.ssp (one of SSP_NAMES) from the two built FMUs (experiments.ssp)."""
    from ..experiments.ssp import (SPEED_LOOP_CAM, SPEED_LOOP_CONTROLLER, compliant_loop_system, speed_loop_system,
                                   write_ssp)

    if name not in SSP_NAMES:
        raise BuildError(f"system {name!r}: allowed {', '.join(map(repr, SSP_NAMES))}")
    system = speed_loop_system(SPEED_LOOP_CAM, SPEED_LOOP_CONTROLLER) if name == SSP_NAME else compliant_loop_system()
    return write_ssp(system, {"cam": cam, "controller": pi_speed}, dest)


def main(argv: List[str] | None = None) -> int:
    from ..experiments.fmu_file import default_model_path

    parser = argparse.ArgumentParser(prog="build_fmu.py", description=__doc__.split("\n\n")[0])
    parser.add_argument("--dest", type=Path, default=None,
                        help="build one FMU (--model, default cam) into this file; without --dest: "
                             "cam.fmu, pi_speed.fmu, speed_loop.ssp and compliant_loop.ssp into models/ in a source checkout "
                             "(else a user cache)")
    parser.add_argument("--model", choices=MODELS, default="cam", help="the FMU --dest builds")
    parser.add_argument("--platforms", default="all",
                        help=f"the C models' binaries: all (default; zig), {binaries.HOST} (this machine, the system "
                             f"C compiler) or a comma-separated list of {', '.join(targets.NAMES)}")
    parser.add_argument("-v", "--verbose", action="store_true", help="list the bundled modules of a Python FMU")
    parser.add_argument("--package-dir", type=Path, default=None, help=argparse.SUPPRESS)
    args = parser.parse_args(argv)
    platforms = None if args.platforms == "all" else args.platforms.split(",")
    try:
        if args.dest is not None:
            print(build(args.dest, args.model, args.verbose, args.package_dir, platforms))
            return 0
        built = {name: build(default_model_path(name), name, args.verbose, args.package_dir, platforms)
                 for name in MODELS}
        for path in built.values():
            print(path)
        for name in SSP_NAMES:
            print(build_ssp(default_model_path(name, ".ssp"), built["cam"], built["pi_speed"], name))
    except (BuildError, RuntimeError) as exc:  # RuntimeError: native.NativeBuildError (no C compiler ...)
        print(f"build_fmu: error: {exc}", file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
