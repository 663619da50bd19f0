"""CSV headers with units: ``omega [rad/s]``; the units come from the variable and parameter tables."""
from __future__ import annotations

from pathlib import Path
from typing import Mapping, Sequence

import numpy as np


def unit_of(name: str) -> str:
    """SI unit of a drive or controller variable or parameter ('time' -> 's'); '' when it has none.

    ``comp.var`` names (co-simulation columns) take the unit of ``var`` in component
    'controller' (control.pi) or any other (the drive's tables).
    """
    from ..control import pi
    from ..physics.parameters import BY_NAME
    from ..physics.variables import FOLLOWER_UNITS, UNITS

    comp, _, var = name.rpartition(".")
    if var == "time":
        return "s"
    if comp == "controller":
        spec = pi.BY_NAME.get(var)
        return pi.UNITS.get(var) or (spec.unit if spec else "")
    spec = BY_NAME.get(var)
    return UNITS.get(var) or FOLLOWER_UNITS.get(var) or (spec.unit if spec else "")


def header(name: str) -> str:
    unit = unit_of(name)
    return f"{name} [{unit}]" if unit else name


def write_csv(columns: Mapping[str, np.ndarray], path: str | Path, order: Sequence[str] | None = None) -> Path:
    """Write ``columns`` (name -> array) with unit headers, 12 significant digits."""
    names = list(order or columns)
    data = np.column_stack([np.asarray(columns[n], dtype=float) for n in names])
    path = Path(path)
    np.savetxt(path, data, delimiter=",", header=",".join(header(n) for n in names), comments="", fmt="%.12g")
    return path
