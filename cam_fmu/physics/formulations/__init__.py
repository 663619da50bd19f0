"""Formulations of the drive, as the readable model that the reference integrates (docs/model.md 5-8).

'consistent' (energy-consistent, the default: ``consistent.HybridDrive``, an ODE
with events that scipy integrates), 'paper' (the published steps 1-9:
``paper.PaperScheme``) and 'speed' (omega imposed: ``speed.speed_drive_outputs``).
The run-time engine is the C one (cam_fmu/engine); these are its independent check.
"""
from __future__ import annotations

from ..drive import DriveModel

FORMULATIONS = ("consistent", "paper", "speed")
# Discrete algorithms: their reference is the same algorithm (FMU and reference agree to rounding).
OWN_REFERENCE = frozenset({"paper", "speed"})


def formulation_name(model: DriveModel) -> str:
    """The formulation (one of FORMULATIONS) that the parameters ``drive`` and ``formulation`` select."""
    return "speed" if model.drive == "speed" else model.formulation


__all__ = ["FORMULATIONS", "OWN_REFERENCE", "formulation_name"]
