"""``DriveSimulator``: cam.fmu's engine from Python, where the README's API has always imported it.

The drive is the C engine (cam_fmu/engine/csrc), the same code that runs inside
cam.fmu's binary; ``cam_fmu.engine.simulator`` is its ctypes binding. Formulation
and solver come from the parameters ``drive``, ``formulation`` and ``solver``
(docs/model.md, docs/fmu.md).
"""
from __future__ import annotations

from ..engine.simulator import DriveSimulator, run_scene
from ..errors import SimulationError, StepRejected
from ..physics.variables import INPUTS, OUTPUTS

__all__ = ["DriveSimulator", "SimulationError", "StepRejected", "run_scene", "INPUTS", "OUTPUTS"]
