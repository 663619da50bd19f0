"""Checking an FMU before a run reads it (``check_cam_variables``).

Finding and building the project's FMUs and SSPs is ``cam_fmu.fmu.build`` (``ensure_fmu``, ``ensure_ssp``,
``default_fmu_path``, ...); their former path here is kept for existing imports.
"""
from __future__ import annotations

from pathlib import Path

from ..fmu.build import (FmuFileError, check_fmu_file, default_fmu_path, default_model_path,  # noqa: F401
                         ensure_fmu, ensure_ssp, fmi_version, shipped_path, source_checkout)


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
