"""The top speed for a residual tolerance, against the cycloidal's closed form scanned by the test."""
from __future__ import annotations

import math

import numpy as np
import pytest

from cam_fmu.kinematics.presets import named_law
from cam_fmu.vibration.limit import largest_failing_ratio, top_speed_rpm
from cam_fmu.vibration.train import residual_ode


def cycloidal(r):
    r = np.asarray(r, dtype=float)
    return np.abs(np.sin(np.pi * r)) / (np.pi * r * np.abs(r * r - 1.0))


@pytest.mark.parametrize("tolerance", [3e-2, 1e-2, 1e-3])
def test_cycloidal_limit_against_its_closed_form(tolerance):
    got = largest_failing_ratio(named_law("cycloidal"), tolerance).r_limit
    # the last r where the closed form exceeds the tolerance, on a fine grid of the test's own, up to the bound
    # 1 / (pi r (r^2 - 1)) <= tolerance beyond which |sin| <= 1 keeps it within
    bound = 1.01
    while 1.0 / (math.pi * bound * (bound * bound - 1.0)) > tolerance:
        bound += 0.01
    r = np.linspace(1.0 + 1e-6, bound, 2_000_001)
    last = r[np.nonzero(cycloidal(r) > tolerance)[0][-1]]
    assert abs(got - last) < 1e-5
    assert cycloidal(got) == pytest.approx(tolerance, rel=1e-9)
    # the integrated train agrees just beyond it: within the tolerance; just before: over it
    ode = residual_ode(named_law("cycloidal"), [got - 1e-4, got + 1e-4])
    assert ode[0] > tolerance > ode[1]


def test_top_speed_is_the_speed_whose_rise_lasts_r_limit_periods():
    rpm = top_speed_rpm(2.5, math.pi / 2, 40.0)
    omega = rpm * 2 * math.pi / 60
    assert (math.pi / 2) / omega * 40.0 == pytest.approx(2.5, rel=1e-14)
    assert top_speed_rpm(0.0, 1.0, 1.0) == math.inf


@pytest.mark.parametrize("bad", [0.0, -1e-3, 1.0, float("nan")])
def test_refused_tolerance(bad):
    with pytest.raises(ValueError, match="--limit .*allowed a residual / lift in \\(0, 1\\)"):
        largest_failing_ratio(named_law("cycloidal"), bad)
