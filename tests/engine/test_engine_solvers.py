"""engine/solvers.py's table against the engine: one entry per solver choice, and ``adaptive`` is what
the C method does (its step count follows rtol), not a claim."""
from __future__ import annotations

import pytest

from cam_fmu.engine.simulator import DriveSimulator
from cam_fmu.engine.solvers import SOLVERS


@pytest.mark.parametrize("name", list(SOLVERS))
def test_adaptive_means_the_step_count_follows_rtol(name):
    counts = []
    for rtol in (1e-4, 1e-10):
        sim = DriveSimulator({"solver": name, "rtol": rtol, "atol": rtol / 100})
        for k in range(200):
            sim.do_step(k * 1e-3, 1e-3, 3.5, 1.0)
        counts.append(sim.steps_taken)
    assert (counts[0] < counts[1]) == SOLVERS[name].adaptive, counts
