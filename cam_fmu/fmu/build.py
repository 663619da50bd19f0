"""Build the project's models: cam.fmu, cam3.fmu, pi_speed.fmu and the loops speed_loop.ssp, compliant_loop.ssp.

    python build_fmu.py                          # -> models/cam.fmu, cam3.fmu, pi_speed.fmu, *.ssp
    python -m cam_fmu.fmu.build --dest /tmp/x/cam.fmu
    python -m cam_fmu.fmu.build --model pi_speed --dest /tmp/x/pi_speed.fmu

Every FMU is a C model on the shared FMI glue, compiled into a binary FMU that
needs nothing but the C library (``engine_fmu``; docs/fmu.md):
- cam.fmu (FMI 2.0, co-simulation and Model Exchange) and cam3.fmu (FMI 3.0
  co-simulation): the drive's C engine;
- pi_speed.fmu (FMI 2.0 co-simulation): the PI speed controller (control/csrc);
- speed_loop.ssp and compliant_loop.ssp: the two closing a loop (``experiments.ssp``).
"""
from __future__ import annotations

import argparse
import sys
from pathlib import Path
from typing import List, Sequence

from ..engine import targets
from . import binaries, engine_fmu

PACKAGE_DIR = Path(__file__).resolve().parents[1]  # this cam_fmu
# every FMU the project builds: name -> (its C model, FMI version)
ENGINE_MODELS = {"cam": ("cam", 2), "cam3": ("cam", 3), "pi_speed": ("pi_speed", 2)}
MODELS = tuple(ENGINE_MODELS)
SSP_NAME = "speed_loop"  # models/speed_loop.ssp: pi_speed.fmu closing a speed loop around cam.fmu
SSP_NAMES = (SSP_NAME, "compliant_loop")  # and the loop on the cam's speed around a compliant shaft


class BuildError(RuntimeError):
    """A model could not be built; the message says why."""


def sources(model: str = "cam") -> list[Path]:
    """Every file whose content ends up in (or shapes) the FMU of ``model``."""
    return engine_fmu.sources(ENGINE_MODELS[model][0])


def is_stale(fmu: Path, model: str = "cam") -> bool:
    """True when ``fmu`` is missing or was built from other sources: its GUID (a hash of everything that
    shapes it, ``engine_fmu.digest``) is not the one this checkout's sources give. The one staleness rule, a
    content hash, as the engine library's file name is."""
    import zipfile
    from xml.etree import ElementTree as ET

    fmu = Path(fmu)
    if not fmu.is_file():
        return True
    try:
        with zipfile.ZipFile(fmu) as z:
            root = ET.fromstring(z.read("modelDescription.xml"))
    except (zipfile.BadZipFile, KeyError, ET.ParseError):
        return True
    built = root.get("guid") or root.get("instantiationToken")
    return built != engine_fmu.model_guid(ENGINE_MODELS[model][0])


def shipped_files() -> list[Path]:
    """The FMUs and SSPs a distribution wheel carries (``models/`` of this checkout, built first where stale)."""
    from ..experiments.fmu_file import ensure_fmu, ensure_ssp

    return [*(ensure_fmu(None, model=name) for name in MODELS), *(ensure_ssp(name) for name in SSP_NAMES)]


def build_wheels(folder: Path, names: Sequence[str] | None = None) -> list[Path]:
    """One wheel per target of engine/targets.py (``names``; default all) into ``folder``: py3-none-<platform>,
    the engine library compiled by zig for it and the shipped FMUs and SSPs (setup.py). Returns the wheels."""
    import os
    import subprocess

    folder = Path(folder).resolve()
    folder.mkdir(parents=True, exist_ok=True)
    shipped_files()  # built once here, not once per wheel
    made = []
    for name in names or targets.NAMES:
        row = targets.get(name)
        proc = subprocess.run([sys.executable, "-m", "pip", "wheel", ".", "--no-deps", "--no-build-isolation", "-q",
                               "-w", str(folder)], cwd=PACKAGE_DIR.parent, capture_output=True, text=True,
                              env={**os.environ, "CAM_FMU_ENGINE_TARGET": name}, timeout=1800)
        wheels = sorted(folder.glob(f"cam_fmu-*-py3-none-{row.wheel}.whl"))
        if proc.returncode != 0 or not wheels:
            raise BuildError(f"the {name} wheel: pip wheel failed (exit {proc.returncode}):\n{proc.stderr[-3000:]}")
        made.append(wheels[0])
    return made


def build(dest: Path, model: str = "cam", platforms: Sequence[str] | None = None) -> Path:
    """Build the FMU of ``model`` (one of MODELS) at ``dest`` (a path ending in .fmu) and return it.
    ``platforms``: its binaries' targets (engine/targets.py; default all, ``["host"]``: this machine only)."""
    if model not in MODELS:
        raise BuildError(f"model {model!r}: allowed {', '.join(map(repr, MODELS))}")
    c_model, fmi_version = ENGINE_MODELS[model]
    try:
        return engine_fmu.build(dest, fmi_version=fmi_version, model=c_model, platforms=platforms)
    except (engine_fmu.FmuBuildError, targets.TargetError) as exc:
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
                             "cam.fmu, cam3.fmu, pi_speed.fmu, speed_loop.ssp and compliant_loop.ssp into models/ in a "
                             "source checkout (else a user cache)")
    parser.add_argument("--model", choices=MODELS, default="cam", help="the FMU --dest builds")
    parser.add_argument("--wheels", type=Path, default=None, metavar="DIR",
                        help="build the package's wheels into DIR: one per platform of engine/targets.py (or those "
                             "of --platforms), each with its engine library and the shipped FMUs and SSPs")
    parser.add_argument("--platforms", default="all",
                        help=f"the binaries: all (default; zig), {binaries.HOST} (this machine, the system "
                             f"C compiler) or a comma-separated list of {', '.join(targets.NAMES)}")
    args = parser.parse_args(argv)
    platforms = None if args.platforms == "all" else args.platforms.split(",")
    try:
        if args.wheels is not None:
            for wheel in build_wheels(args.wheels, platforms):
                print(wheel)
            return 0
        if args.dest is not None:
            print(build(args.dest, args.model, platforms))
            return 0
        built = {name: build(default_model_path(name), name, platforms) for name in MODELS}
        for path in built.values():
            print(path)
        for name in SSP_NAMES:
            print(build_ssp(default_model_path(name, ".ssp"), built["cam"], built["pi_speed"], name))
    except (BuildError, RuntimeError) as exc:  # RuntimeError: the engine's build (no C compiler ...)
        print(f"build_fmu: error: {exc}", file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
