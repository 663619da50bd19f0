"""Formulations of the drive: one class each, one registry.

``FORMULATIONS`` maps a name to its class: 'consistent' (energy-consistent,
the default), 'paper' (the published steps 1-9) and 'speed' (omega imposed).
``formulation_for(model)`` is the one place that chooses among them from the
parameters ``drive`` and ``formulation``. A new formulation is one class with
the ``base.Formulation`` methods plus one entry here.
"""
from __future__ import annotations

from typing import Any

from ..drive import DriveModel
from .base import Formulation
from .consistent_voltage import ConsistentVoltage
from .paper import PaperVoltage
from .speed import SpeedDrive

FORMULATIONS: dict[str, type[Formulation]] = {
    "consistent": ConsistentVoltage,
    "paper": PaperVoltage,
    "speed": SpeedDrive,
}


def formulation_name(model: DriveModel) -> str:
    """The key in FORMULATIONS that the parameters ``drive`` and ``formulation`` select."""
    return "speed" if model.drive == "speed" else model.formulation


def formulation_for(model: DriveModel, u: float, omega_ref: float, kernel: Any) -> Formulation:
    """The formulation the model's parameters ask for, built at the given start inputs.

    ``kernel``: the engine's drive kernel of ``model``, where the consistent formulation keeps its state.
    """
    cls = FORMULATIONS[formulation_name(model)]
    if cls is ConsistentVoltage:
        return ConsistentVoltage(model, u, kernel)
    return cls(model, omega_ref) if cls is SpeedDrive else cls(model, u)


__all__ = ["FORMULATIONS", "Formulation", "formulation_for", "formulation_name"]
