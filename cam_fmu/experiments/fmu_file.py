"""The one place that finds or builds cam.fmu.

In a source checkout (a ``build_fmu.py`` beside the package) the FMU is
``models/cam.fmu``; in an installed package it lives in the user cache
(``$XDG_CACHE_HOME/cam_fmu``, else ``~/.cache/cam_fmu``), named by the package
version. Either way it is (re)built from the package's own sources when
missing or older than them.
"""
from __future__ import annotations

import os
import subprocess
import sys
import tempfile
from pathlib import Path
from typing import Callable

PACKAGE_DIR = Path(__file__).resolve().parents[1]


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
    import zipfile

    try:
        with zipfile.ZipFile(path) as z:
            if "modelDescription.xml" not in z.namelist():
                raise FmuFileError(f"{str(path)!r} is not an FMU: no modelDescription.xml inside")
    except zipfile.BadZipFile:
        raise FmuFileError(f"{str(path)!r} is not an FMU (not a zip archive)") from None


def ensure_fmu(path: str | Path | None = None, log: Callable[[str], None] | None = None,
               model: str = "cam") -> Path:
    """The FMU to run: ``path`` as given (it must exist), or the default one, built when stale.

    The build runs in a subprocess (it imports the slave as a top-level module
    and pythonfmu edits sys.path) and replaces the file atomically.
    """
    if path is not None:
        path = Path(path)
        if not path.is_file():
            raise FmuFileError(f"FMU {str(path)!r} does not exist")
        check_fmu_file(path)
        return path
    from ..fmu.build import is_stale

    path = default_model_path(model)
    if path == shipped_path(model) or not is_stale(path, model=model):
        return path  # a wheel's prebuilt FMU is its own: never rebuilt (it needs no compiler)
    if log is not None:
        log(f"# building {path} (missing or older than its sources)")
    path.parent.mkdir(parents=True, exist_ok=True)
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
    return path


def ensure_ssp(path: str | Path | None = None, log: Callable[[str], None] | None = None) -> Path:
    """A shipped SSP: ``path`` as given (it must exist; a shipped system's name, e.g. compliant_loop, names
    models/<name>.ssp), or models/speed_loop.ssp, rebuilt when missing or older than one of its FMUs (which
    ensure_fmu rebuilds when stale) or than ssp.py (its writer)."""
    from ..fmu.build import SSP_NAME, SSP_NAMES, build_ssp

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
    from . import ssp as writer

    inputs = [*fmus.values(), Path(writer.__file__)]
    if path.is_file() and all(path.stat().st_mtime >= f.stat().st_mtime for f in inputs):
        return path
    if log is not None:
        log(f"# writing {path}")
    return build_ssp(path, fmus["cam"], fmus["pi_speed"], name)


def fmi_version(path: str | Path) -> str:
    """The fmiVersion attribute of an FMU's modelDescription.xml ('?' where there is none to read)."""
    import zipfile
    from xml.etree import ElementTree as ET

    try:
        with zipfile.ZipFile(path) as z:
            return ET.fromstring(z.read("modelDescription.xml")).get("fmiVersion", "?")
    except (zipfile.BadZipFile, KeyError, ET.ParseError, OSError):
        return "?"


def check_cam_variables(path: str | Path, option: str = "--fmu") -> Path:
    """``path`` if it is an FMI 2.0 or 3.0 co-simulation FMU with cam.fmu's inputs, outputs and parameters, else
    FmuFileError naming what it lacks: checked before a run that reads them (the bench, a sweep), not after
    minutes of work."""
    from fmpy import read_model_description

    from ..physics.parameters import BY_NAME
    from ..physics.variables import INPUT_NAMES, OUTPUT_NAMES

    from .fmpy_runner import SUPPORTED, FmuRunError, check_runnable

    version = fmi_version(path)
    if version != "?" and version not in SUPPORTED:  # before fmpy validates it against another version's schema
        raise FmuFileError(f"{option} {str(path)!r}: an FMI {version} FMU; runnable are FMI 2.0 and 3.0 "
                           "co-simulation FMUs (cam.fmu, cam3.fmu)")
    try:
        md = read_model_description(str(path))
    except Exception as exc:  # noqa: BLE001 - fmpy raises several kinds for a file that is not an FMU
        raise FmuFileError(f"{option} {str(path)!r} is not an FMU: {' '.join(str(exc).split())}") from None
    try:
        check_runnable(md, f"{option} {str(path)!r}")
    except FmuRunError as exc:
        raise FmuFileError(str(exc)) from None
    names = {v.name for v in md.modelVariables}
    missing = [n for n in (*INPUT_NAMES, *OUTPUT_NAMES, *BY_NAME) if n not in names]
    if missing:
        raise FmuFileError(f"{option} {str(path)!r} is not a cam.fmu: it lacks {len(missing)} of cam.fmu's "
                           f"variables ({', '.join(missing[:6])}{', ...' if len(missing) > 6 else ''})")
    return Path(path)
