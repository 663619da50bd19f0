"""DriveSimulator.do_step(t, h) checks t by fmi2DoStep's rule: t is where the drive is, to within
1e-9 max(1, |time|) (the rounding of a host's summed steps); anything else is a SimulationError naming both
times, and changes nothing (cam_drive_do_step, csrc/src/drive.c)."""
from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from cam_fmu.engine.simulator import DriveSimulator
from cam_fmu.errors import SimulationError


def _after(steps: int, **kwargs) -> DriveSimulator:
    sim = DriveSimulator({}, **kwargs)
    t0 = kwargs.get("start_time", 0.0)
    for k in range(steps):
        sim.do_step(t0 + k * 1e-3, 1e-3, 3.5, 1.0)
    return sim


@pytest.mark.parametrize("t", [math.nan, math.inf, -math.inf, -1.0, 5.0, 1e300])
def test_a_communication_point_that_is_not_the_drives_time_is_refused(t):
    """NaN, inf, -1, 5 and 1e300 were accepted; with NaN, get_state() gave a state its own set_state refused."""
    sim = _after(10)
    saved, out = sim.get_state(), sim.outputs()
    with pytest.raises(SimulationError, match=r"communication point t = .* s is not where the drive is, "
                                              r"t = 0\.01\d* s \(allowed difference 1e-09 s\)"):
        sim.do_step(t, 1e-3, 3.5, 1.0)
    assert sim.get_state() == saved and sim.outputs() == out and sim.time == saved["time"]
    sim.set_state(sim.get_state())  # its own state restores
    sim.do_step(sim.time, 1e-3, 3.5, 1.0)  # and the drive goes on from where it is
    assert sim.time == pytest.approx(0.011, abs=1e-15)


def test_the_same_rule_holds_in_a_run_of_many_steps():
    """DriveSimulator.run (cam_drive_run): a row whose t skips ahead is refused at that row."""
    sim = DriveSimulator({})
    rows = [(k * 1e-3, 1e-3, 3.5, 1.0, 0.0) for k in range(5)]
    rows[3] = (3.5e-3, 1e-3, 3.5, 1.0, 0.0)
    with pytest.raises(SimulationError, match="is not where the drive is"):
        sim.run(rows)
    assert sim.time == pytest.approx(3e-3, abs=1e-15)


@settings(max_examples=80, deadline=None)
@given(steps=st.integers(0, 30), start=st.sampled_from([0.0, -2.0, 1.7e9]),
       offset=st.floats(-1e-6, 1e-6) | st.floats(-1e3, 1e3) | st.sampled_from([math.nan, math.inf, -math.inf]))
def test_property_a_step_is_taken_exactly_when_t_is_within_the_slack_of_the_drives_time(steps, start, offset):
    """Any start time, any number of steps before, any t: taken iff |t - time| <= 1e-9 max(1, |time|) and t is
    finite; the clock then reads t + h (the host's clock wins, as in the FMU)."""
    sim = _after(steps, start_time=start)
    now = sim.time
    t = now + offset
    slack = 1e-9 * max(1.0, abs(now))
    if math.isfinite(t) and abs(t - now) <= slack:
        sim.do_step(t, 1e-3, 3.5, 1.0)
        assert sim.time == t + 1e-3
    else:
        with pytest.raises(SimulationError, match="is not where the drive is"):
            sim.do_step(t, 1e-3, 3.5, 1.0)
        assert sim.time == now


def test_a_late_start_gives_the_same_answer_as_one_at_zero():
    """start_time moves the clock, nothing else: the trajectories agree to the bit."""
    early, late = _after(200), _after(200, start_time=1.7e9)
    assert early.outputs() == late.outputs()
    assert late.time == pytest.approx(1.7e9 + 0.2, rel=1e-15)
    with pytest.raises(SimulationError, match="start time = inf s"):
        DriveSimulator({}, start_time=math.inf)
    assert np.isfinite(list(late.outputs().values())).all()
