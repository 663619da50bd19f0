"""Formulations of the drive: one class each, one registry.

``FORMULATIONS`` maps a name to its class: 'consistent' (energy-consistent,
the default), 'paper' (the published steps 1-9) and 'speed' (omega imposed).
``formulation_for(model)`` is the one place that chooses among them from the
parameters ``drive`` and ``formulation``. A new formulation is one class with
the ``base.Formulation`` methods plus one entry here.
"""
from __future__ import annotations

from ..drive import DriveModel
from .base import Formulation
from .consistent import ConsistentVoltage
from .paper import PaperVoltage
from .speed import SpeedDrive

FORMULATIONS: dict[str, type[Formulation]] = {
    "consistent": ConsistentVoltage,
    "paper": PaperVoltage,
    "speed": SpeedDrive,
}


def formulation_for(model: DriveModel, u: float, omega_ref: float) -> Formulation:
    """The formulation the model's parameters ask for, built at the given start inputs."""
    if model.drive == "speed":
        return SpeedDrive(model, omega_ref)
    return FORMULATIONS[model.formulation](model, u)


__all__ = ["FORMULATIONS", "Formulation", "formulation_for"]
