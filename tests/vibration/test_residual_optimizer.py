"""optimize-law's search: its law re-evaluated by the integrated train (the independent route), its bounds
checked by the law's characteristic values, the issue's measurement on r = 1.5..3 as the target."""
from __future__ import annotations

import math

import numpy as np
import pytest

from cam_fmu.kinematics.characteristics import characteristics
from cam_fmu.kinematics.motion_law import MotionLaw
from cam_fmu.kinematics.presets import named_law
from cam_fmu.vibration.optimize import DEFAULT_CA, optimize_law, pareto_front
from cam_fmu.vibration.train import residual_ode

BAND = (1.5, 3.0)
MS_JERK = characteristics(named_law("modified_sine")).Jm


@pytest.fixture(scope="module")
def modified_sine_worst() -> float:
    """The modified sine's worst residual over the band by the integrated train (grid of 0.01, refined)."""
    law = named_law("modified_sine")
    r = np.arange(BAND[0], BAND[1] + 1e-9, 0.01)
    R = residual_ode(law, r)
    k = int(np.argmax(R))
    fine = np.linspace(r[max(k - 1, 0)], r[min(k + 1, r.size - 1)], 41)
    return float(max(R.max(), residual_ode(law, fine).max()))


def ode_check(best) -> float:
    """The integrated train: at the optimiser's worst r it gives the optimiser's worst; nowhere on a grid of the
    band (0.01) more. Returns that worst."""
    law = MotionLaw(best.T)
    at_worst = float(residual_ode(law, best.r_worst)[0])
    assert at_worst == pytest.approx(best.worst, abs=1e-9)
    assert residual_ode(law, np.arange(BAND[0], BAND[1] + 1e-9, 0.01)).max() <= best.worst + 1e-9
    return at_worst


@pytest.mark.parametrize("max_cj, ratio", [(MS_JERK, 0.873), (150.0, 0.69), (None, 0.56)])
def test_at_least_as_good_as_the_issue_measured(max_cj, ratio, modified_sine_worst):
    """The issue: about 0.87x the modified sine at its jerk, 0.69x at Cj = 150, about 0.56x unbounded."""
    assert modified_sine_worst == pytest.approx(0.078, abs=5e-4)
    best = optimize_law(*BAND, max_cj=max_cj)
    worst = ode_check(best)     # the optimiser's number, by the other route
    assert worst <= ratio * modified_sine_worst
    c = characteristics(MotionLaw(best.T))
    assert c.Am <= DEFAULT_CA * (1 + 1e-9)
    if max_cj is not None:
        assert not c.jerk_unbounded and c.Jm <= max_cj * (1 + 1e-9)


def test_the_front_never_gets_worse_as_the_jerk_bound_grows():
    front = pareto_front(*BAND, [40.0, 60.0, 100.0, 200.0, 400.0, None])
    assert [o.max_cj for o in front] == [40.0, 60.0, 100.0, 200.0, 400.0, None]
    worst = [o.worst for o in front]
    assert all(b <= a * (1 + 1e-9) for a, b in zip(worst, worst[1:]))
    for o in front:
        c = characteristics(MotionLaw(o.T))
        assert o.max_cj is None or c.Jm <= o.max_cj * (1 + 1e-9)


def test_a_tighter_acceleration_bound_is_met():
    best = optimize_law(*BAND, max_ca=6.0, max_cj=None)
    assert characteristics(MotionLaw(best.T)).Am <= 6.0 * (1 + 1e-9)


@pytest.mark.parametrize("band", [(0.0, 2.0), (-1.0, 2.0), (2.0, 1.0), (1.0, math.inf)])
def test_refused_band(band):
    with pytest.raises(ValueError, match="--band .*0 < R1 < R2"):
        optimize_law(*band)


def test_refused_unreachable_acceleration_bound():
    with pytest.raises(ValueError, match="--max-ca 3.9: unreachable.*below 4"):
        optimize_law(*BAND, max_ca=3.9)


def test_refused_bounds_unreachable_together():
    # a jerk bound below the cycloidal's 4 pi^2 with Ca near constant acceleration's 4: no law meets both
    with pytest.raises(ValueError, match="unreachable together"):
        optimize_law(*BAND, max_ca=4.05, max_cj=20.0)
