"""Build the project's models: cam.fmu, cam3.fmu, pi_speed.fmu and the loops speed_loop.ssp, compliant_loop.ssp.

    python build_fmu.py                          # -> models/cam.fmu, cam3.fmu, pi_speed.fmu, *.ssp
    python -m cam_fmu.fmu.build --dest /tmp/x/cam.fmu
    python -m cam_fmu.fmu.build --model pi_speed --dest /tmp/x/pi_speed.fmu

Every FMU is a C model on the shared FMI glue, compiled into a binary FMU that
needs nothing but the C library (``engine_fmu``; docs/fmu.md):
- cam.fmu (FMI 2.0, co-simulation and Model Exchange) and cam3.fmu (FMI 3.0
  co-simulation): the drive's C engine;
- pi_speed.fmu (FMI 2.0 co-simulation): the PI speed controller (control/csrc);
- speed_loop.ssp and compliant_loop.ssp: the two closing a loop (``ssp``).

It is also the one place that finds or builds them for a run (``ensure_fmu``, ``ensure_ssp``): in a source
checkout (a ``build_fmu.py`` beside the package) they are ``models/<name>``; in an installed package the
wheel's prebuilt files (``cam_fmu/shipped``), else the user cache (``$XDG_CACHE_HOME/cam_fmu``, else
``~/.cache/cam_fmu``), named by the package version. Either way an FMU is (re)built from the package's own
sources when missing or built from other sources.
"""
from __future__ import annotations

import argparse
import os
import subprocess
import sys
import tempfile
import zipfile
from pathlib import Path
from typing import Callable, List, Sequence
from xml.etree import ElementTree as ET

from ..engine import reproducible, targets
from . import binaries, build_lock, engine_fmu, ssp

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


class FmuFileError(RuntimeError):
    """The FMU could not be found or built; the message says why."""


def source_checkout() -> Path | None:
    """The repository root when the package runs from a checkout, else None."""
    root = PACKAGE_DIR.parent
    return root if (root / "build_fmu.py").is_file() and (root / "pyproject.toml").is_file() else None


def shipped_path(name: str = "cam", suffix: str = ".fmu") -> Path | None:
    """The prebuilt file a distribution wheel carries (``cam_fmu/shipped/<name><suffix>``), else None."""
    path = PACKAGE_DIR / "shipped" / f"{name}{suffix}"
    return path if path.is_file() else None


def default_model_path(name: str = "cam", suffix: str = ".fmu") -> Path:
    """models/<name><suffix> in a checkout, the prebuilt file of an installed wheel, else the user-cache copy
    for this package version."""
    root = source_checkout()
    if root is not None:
        return root / "models" / f"{name}{suffix}"
    shipped = shipped_path(name, suffix)
    if shipped is not None:
        return shipped
    from .. import __version__

    cache = Path(os.environ.get("XDG_CACHE_HOME") or Path.home() / ".cache") / "cam_fmu"
    return cache / f"{name}-{__version__}{suffix}"


def default_fmu_path() -> Path:
    """models/cam.fmu in a checkout, else the user-cache copy for this package version."""
    return default_model_path("cam")


def check_fmu_file(path: Path) -> None:
    """FmuFileError unless ``path`` is a zip archive with a modelDescription.xml (an FMU)."""
    try:
        with zipfile.ZipFile(path) as z:
            if "modelDescription.xml" not in z.namelist():
                raise FmuFileError(f"{str(path)!r} is not an FMU: no modelDescription.xml inside")
    except zipfile.BadZipFile:
        raise FmuFileError(f"{str(path)!r} is not an FMU (not a zip archive)") from None


def ensure_fmu(path: str | Path | None = None, log: Callable[[str], None] | None = None,
               model: str = "cam") -> Path:
    """The FMU to run: ``path`` as given (it must exist), or the default one, built when stale.

    The build runs in a subprocess (``python -m cam_fmu.fmu.build``) and replaces the file atomically.
    """
    if path is not None:
        path = Path(path)
        if not path.is_file():
            raise FmuFileError(f"FMU {str(path)!r} does not exist")
        check_fmu_file(path)
        return path
    path = default_model_path(model)
    if path == shipped_path(model) or not is_stale(path, model=model):
        return path  # a wheel's prebuilt FMU is its own: never rebuilt (it needs no compiler)
    with build_lock.building(path.parent):  # another process building it: wait, then it is up to date
        if not is_stale(path, model=model):
            return path
        _build_into(path, model, log)
    return path


def _build_into(path: Path, model: str, log: Callable[[str], None] | None) -> None:
    """Build ``model`` into ``path`` (ensure_fmu, holding the folder's build lock)."""
    if log is not None:
        log(f"# building {path} (missing or older than its sources)")
    with tempfile.TemporaryDirectory(prefix="cam_fmu_build_", dir=path.parent) as tmp:
        dest = Path(tmp) / f"{model}.fmu"
        # a checkout's models/ get every platform (zig); the user cache of an installed package, this machine's
        platforms = [] if source_checkout() is not None else ["--platforms", "host"]
        proc = subprocess.run([sys.executable, "-m", "cam_fmu.fmu.build", "--model", model, "--dest", str(dest),
                               *platforms],
                              capture_output=True, text=True, cwd=str(PACKAGE_DIR.parent), timeout=600)
        if proc.returncode != 0 or not dest.is_file():
            raise FmuFileError(f"building {path} failed (exit {proc.returncode}):\n{proc.stdout}\n{proc.stderr}")
        os.replace(dest, path)  # atomic: a process reading the old file keeps it


def ensure_ssp(path: str | Path | None = None, log: Callable[[str], None] | None = None) -> Path:
    """A shipped SSP: ``path`` as given (it must exist; a shipped system's name, e.g. compliant_loop, names
    models/<name>.ssp), or models/speed_loop.ssp, rebuilt when missing or older than one of its FMUs (which
    ensure_fmu rebuilds when stale) or than fmu/ssp.py (its writer)."""
    name = SSP_NAME
    if path is not None:
        if str(path) in SSP_NAMES and not Path(path).is_file():
            name = str(path)
        else:
            path = Path(path)
            if not path.is_file():
                raise FmuFileError(f"SSP file {str(path)!r} does not exist (shipped systems: {', '.join(SSP_NAMES)})")
            return path
    path = default_model_path(name, ".ssp")
    if path == shipped_path(name, ".ssp"):
        return path  # a wheel's prebuilt SSP, with its prebuilt FMUs
    fmus = {model: ensure_fmu(None, log, model) for model in ("cam", "pi_speed")}  # the loop's two FMUs
    inputs = [*fmus.values(), Path(ssp.__file__)]
    with build_lock.building(path.parent):  # one writer; a second finds it written
        if path.is_file() and all(path.stat().st_mtime >= f.stat().st_mtime for f in inputs):
            return path
        if log is not None:
            log(f"# writing {path}")
        return build_ssp(path, fmus["cam"], fmus["pi_speed"], name)


def fmi_version(path: str | Path) -> str:
    """The fmiVersion attribute of an FMU's modelDescription.xml ('?' where there is none to read)."""
    try:
        with zipfile.ZipFile(path) as z:
            return ET.fromstring(z.read("modelDescription.xml")).get("fmiVersion", "?")
    except (zipfile.BadZipFile, KeyError, ET.ParseError, OSError):
        return "?"


def shipped_files(log: Callable[[str], None] | None = None) -> list[Path]:
    """The FMUs and SSPs a distribution wheel carries (``models/`` of this checkout, built first where stale;
    ``log``: told what is built)."""
    return [*(ensure_fmu(None, log, model=name) for name in MODELS), *(ensure_ssp(name, log) for name in SSP_NAMES)]


def build_wheels(folder: Path, names: Sequence[str] | None = None,
                 progress: binaries.Progress | None = None) -> list[Path]:
    """One wheel per target of engine/targets.py (``names``; default all) into ``folder``: py3-none-<platform>,
    the engine library compiled by zig for it and the shipped FMUs and SSPs (setup.py). Returns the wheels.
    ``progress(done, total, note=...)``: told which wheel is being built (binaries.Progress)."""
    folder = Path(folder).resolve()
    folder.mkdir(parents=True, exist_ok=True)
    shipped_files(None if progress is None else lambda m: print(m, file=sys.stderr))  # once here, not per wheel
    made = []
    names = list(names or targets.NAMES)
    for k, name in enumerate(names):
        if progress is not None:
            progress(k, len(names), note=f"building {name}")
        row = targets.get(name)
        proc = subprocess.run([sys.executable, "-m", "pip", "wheel", ".", "--no-deps", "--no-build-isolation", "-q",
                               "-w", str(folder)], cwd=PACKAGE_DIR.parent, capture_output=True, text=True,
                              env={**reproducible.build_env(), "CAM_FMU_ENGINE_TARGET": name}, timeout=1800)
        wheels = sorted(folder.glob(f"cam_fmu-*-py3-none-{row.wheel}.whl"))
        if proc.returncode != 0 or not wheels:
            raise BuildError(f"the {name} wheel: pip wheel failed (exit {proc.returncode}):\n{proc.stderr[-3000:]}")
        made.append(wheels[0])
    if progress is not None:
        progress(len(names), len(names), note="")
    return made


def build(dest: Path, model: str = "cam", platforms: Sequence[str] | None = None,
          progress: binaries.Progress | None = None) -> Path:
    """Build the FMU of ``model`` (one of MODELS) at ``dest`` (a path ending in .fmu) and return it.
    ``platforms``: its binaries' targets (engine/targets.py; default all, ``["host"]``: this machine only);
    ``progress(done, total, note=...)``: told which platform is being built (binaries.Progress)."""
    if model not in MODELS:
        raise BuildError(f"model {model!r}: allowed {', '.join(map(repr, MODELS))}")
    c_model, fmi_version = ENGINE_MODELS[model]
    try:
        return engine_fmu.build(dest, fmi_version=fmi_version, model=c_model, platforms=platforms, progress=progress)
    except (engine_fmu.FmuBuildError, targets.TargetError) as exc:
        raise BuildError(str(exc)) from None


def build_ssp(dest: Path, cam: Path, pi_speed: Path, name: str = SSP_NAME) -> Path:
    """models/<name>.ssp (one of SSP_NAMES) from the two built FMUs (the systems of ``ssp``)."""
    if name not in SSP_NAMES:
        raise BuildError(f"system {name!r}: allowed {', '.join(map(repr, SSP_NAMES))}")
    system = ssp.speed_loop_system(ssp.SPEED_LOOP_CAM, ssp.SPEED_LOOP_CONTROLLER) if name == SSP_NAME \
        else ssp.compliant_loop_system()
    return ssp.write_ssp(system, {"cam": cam, "controller": pi_speed}, dest)


def main(argv: List[str] | None = None, progress: Callable[[str], binaries.Progress] | None = None) -> int:
    """The build's command line. ``progress(label)``: a progress callback for one FMU or the wheels, with
    ``close()`` (build_fmu.py passes experiments.progress.ProgressBar: a bar on stderr naming the FMU and the
    platform being built; without it, nothing but the paths built, on stdout)."""
    def bar(label: str):
        return progress(label) if progress is not None else None

    def done(one) -> None:
        if one is not None:
            one.close()

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
            one = bar("build wheels")
            try:
                wheels = build_wheels(args.wheels, platforms, one)
            finally:
                done(one)
            for wheel in wheels:
                print(wheel)
            return 0
        todo = {args.model: args.dest} if args.dest is not None else {name: default_model_path(name) for name in MODELS}
        built = {}
        for name, dest in todo.items():
            one = bar(f"build {name}.fmu (FMI {ENGINE_MODELS[name][1]}.0)")
            try:
                built[name] = build(dest, name, platforms, one)
            finally:
                done(one)
        if args.dest is not None:
            print(built[args.model])
            return 0
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
