"""A run of the C engine in the reference's terms: ``simulate_engine`` takes ``simulate_reference``'s arguments
(parameters, stop time, output interval, the input signals, tolerances, a train) and returns its kind of columns,
so a measurement written against the reference (reference/train_residual.py's ``drive_residual``) runs on the
engine unchanged. The engine steps from output point to output point with the inputs of each step's start (a
ramp of omega_ref as its slope, exactly)."""
from __future__ import annotations

from typing import Any, Mapping

import numpy as np

from ..physics.signals import Signal, constant
from ..physics.variables import INPUT_STARTS
from ..reference.integrate import output_grid

__all__ = ["simulate_engine"]


def simulate_engine(params: Mapping[str, Any] | None, stop_time: float, output_interval: float,
                    u: Signal | None = None, omega_ref: Signal | None = None, rtol: float | None = None,
                    atol: float | None = None, train: Any = None) -> dict[str, np.ndarray]:
    """The engine's outputs at 0, output_interval, .. and stop_time [s] (a last, shorter interval ends there), as
    ``simulate_reference`` gives them; ``rtol``, ``atol`` (None: the parameters') and ``train`` (a
    physics.train.Train: its k_train, d_train, m_end) set the parameters of the same names."""
    from ..fmu.engine import DriveSimulator

    p = dict(params or {})
    if train is not None:
        p.update(k_train=train.k_train, d_train=train.d_train, m_end=train.m_end)
    p.update({k: v for k, v in (("rtol", rtol), ("atol", atol)) if v is not None})
    u = u or constant(INPUT_STARTS["u"])
    omega_ref = omega_ref or constant(INPUT_STARTS["omega_ref"])
    grid = output_grid(stop_time, output_interval)   # the reference's times
    sim = DriveSimulator(p)
    sim.set_inputs(u.value(0.0), omega_ref.value(0.0), omega_ref.slope(0.0))
    rows = [sim.outputs()]
    for a, b in zip(grid[:-1], grid[1:]):
        sim.do_step(a, b - a, u=u.value(a), omega_ref=omega_ref.value(a), omega_dot_ref=omega_ref.slope(a))
        rows.append(sim.outputs())
    return {"time": grid, **{name: np.array([r[name] for r in rows]) for name in rows[0]}}
