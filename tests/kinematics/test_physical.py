"""Peak follower velocity, acceleration and jerk at a cam speed, against closed forms."""

import math

import numpy as np
import pytest

from cam_fmu.kinematics.cam_program import CamProgram, paper_program
from cam_fmu.kinematics.motion_table import TableProgram
from cam_fmu.kinematics.physical import follower_peaks


def test_cycloidal_closed_forms():
    # s = h (t/b - sin(2 pi t/b) / (2 pi)): v = 2h/b w at b/2, a = 2 pi h/b^2 w^2 at b/4,
    # j = 4 pi^2 h/b^3 w^3 at 0.
    h, b, rpm = 0.025, math.radians(90), 300.0
    w = 2 * math.pi * rpm / 60
    prog = CamProgram("cycloidal", "cycloidal", h, b, math.radians(90), math.radians(120), math.radians(60))
    p = follower_peaks(prog, rpm)
    assert p.omega == pytest.approx(w, rel=1e-15)
    assert p.velocity == pytest.approx(2 * h / b * w, rel=1e-12) and p.velocity_at == pytest.approx(b / 2)
    assert p.acceleration == pytest.approx(2 * math.pi * h / b ** 2 * w ** 2, rel=1e-12)
    assert p.acceleration_at == pytest.approx(b / 4)
    assert p.jerk == pytest.approx(4 * math.pi ** 2 * h / b ** 3 * w ** 3, rel=1e-12) and p.jerk_at == 0.0
    assert not p.jerk_unbounded


def test_simple_harmonic_has_unbounded_jerk_and_closed_form_velocity():
    # s = h/2 (1 - cos(pi t/b)): v = pi h/(2b) w, a = pi^2 h/(2 b^2) w^2; A jumps at the ends
    h, b, rpm = 0.01, 1.2, 60.0
    w = 2 * math.pi
    prog = CamProgram("simple_harmonic", "simple_harmonic", h, b, 0.5, b, 2 * math.pi - 0.5 - 2 * b)
    p = follower_peaks(prog, rpm)
    assert p.velocity == pytest.approx(math.pi * h / (2 * b) * w, rel=1e-12)
    assert p.acceleration == pytest.approx(math.pi ** 2 * h / (2 * b * b) * w * w, rel=1e-12)
    assert p.jerk is None and p.jerk_at is None and p.jerk_unbounded
    assert p.to_json_dict()["peak_jerk_m_s3"] is None


def test_paper_profile_peak_velocity():
    # paper_program: peak ds/dtheta = 2 A = 70 mm/rad
    p = follower_peaks(paper_program(), 120.0)
    assert p.velocity == pytest.approx(0.070 * 4 * math.pi, rel=1e-12)


def test_table_program_peaks_against_dense_sampling():
    prog = CamProgram("modified_sine", "cycloidal", 0.02, 1.5, 0.5, 2.0, 2 * math.pi - 4.0)
    th = np.radians(np.arange(0.0, 360.0, 3.0))
    table = TableProgram(th, prog.evaluate(th)[0])
    p = follower_peaks(table, 90.0)
    w = 3 * math.pi
    g = np.linspace(0.0, 2 * math.pi, 400001)
    _, s1, s2, s3 = table.evaluate(g)
    # exact peaks are never below the sampled ones and agree to the grid's resolution
    for peak, sampled in ((p.velocity, np.abs(s1).max() * w), (p.acceleration, np.abs(s2).max() * w ** 2),
                          (p.jerk, np.abs(s3).max() * w ** 3)):
        assert sampled <= peak * (1 + 1e-12) and peak == pytest.approx(sampled, rel=1e-4)
    # and are reached where reported
    assert abs(table.derivatives(p.velocity_at)[1]) * w == pytest.approx(p.velocity, rel=1e-12)
    # s'' jumps at the knots, where a peak may be either one-sided limit: derivatives() gives the
    # left one at the angle, the right one just after it
    at = p.acceleration_at
    sides = (table.derivatives(at)[2], table.derivatives(math.nextafter(at, math.inf))[2])
    assert max(abs(v) for v in sides) * w ** 2 == pytest.approx(p.acceleration, rel=1e-12)


@pytest.mark.parametrize("rpm", [0.0, -10.0, math.nan, math.inf, 1e300])
def test_rpm_must_be_positive(rpm):
    with pytest.raises(ValueError, match=r"allowed \(0, 1e\+06\] rpm"):
        follower_peaks(paper_program(), rpm)
