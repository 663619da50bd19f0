"""Numbers the FMUs and SSPs take from two shipped scene files, read as data (TOML): cam.fmu's default
experiment is the fig. 6 scene's, compliant_loop.ssp's drive the compliant_shaft scene's primary run.

The scenes themselves (their checks, runs, signals, figures) are ``experiments.scenes``, a layer above
this one; ``tests/fmu_cs/test_ssp_file.py`` compares these reads with it.
"""
from __future__ import annotations

from pathlib import Path
from typing import Any

try:
    import tomllib
except ModuleNotFoundError:  # Python 3.10
    import tomli as tomllib

SCENE_DIR = Path(__file__).resolve().parents[1] / "experiments" / "scene_files"


def read(name: str) -> dict[str, Any]:
    """The shipped scene file ``scene_files/<name>.toml`` as a table, unchecked."""
    with open(SCENE_DIR / f"{name}.toml", "rb") as f:
        return tomllib.load(f)


def experiment(name: str) -> tuple[float, float, float]:
    """(start, stop, step) [s]: 0, the scene's stop_time and output_interval."""
    data = read(name)
    return 0.0, float(data["stop_time"]), float(data["output_interval"])


def primary_parameters(name: str) -> dict[str, Any]:
    """The scene's [parameters], its drive and its first run's overrides, as written (the primary run's)."""
    data = read(name)
    runs = data.get("runs") or [{}]
    return {**data.get("parameters", {}), "drive": data.get("drive", "voltage"),
            **{key: value for key, value in runs[0].items() if key != "label"}}
