"""Solvers of the FMU: one module per family, one registry.

``SOLVERS`` maps the parameter value ``solver`` to its Stepper class; the
parameter's allowed choices are checked against it by a test. A new solver is
one class (name, stability factor, ``step``) in a module here plus one entry.
``hybrid.HybridIntegrator`` advances a hybrid system over a communication step
with any of them (events, profile breakpoints, the work bound max_steps).
"""
from __future__ import annotations

from .base import SimulationError, StepRejected, Stepper
from .dopri import DormandPrince45
from .etd import ETDRK4
from .explicit import RK4, Euler

SOLVERS: dict[str, type[Stepper]] = {cls.name: cls for cls in (Euler, RK4, DormandPrince45, ETDRK4)}

__all__ = ["SOLVERS", "SimulationError", "StepRejected", "Stepper"]
