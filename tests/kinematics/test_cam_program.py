"""CamProgram against the paper's six closed-form pieces and basic invariants."""

import math

import numpy as np
import pytest

from cam_fmu.kinematics.cam_program import CamProgram, paper_program
from cam_fmu.kinematics.motion_law import MotionLaw
from cam_fmu.kinematics.presets import PRESETS

A = 0.035
PI = math.pi


def paper_pieces(th):
    """Seed 002 section 2.1, S in metres, with derivatives worked by hand:
    (s, ds, d2s, d3s) at theta in [0, 2 pi]."""
    s4, c4 = math.sin(4 * th), math.cos(4 * th)
    ramp = (A * (th - s4 / 4), A * (1 - c4), 4 * A * s4, 16 * A * c4)
    if th <= PI / 4:
        return ramp
    if th <= 3 * PI / 4:
        return 2 * A * th - PI * A / 4, 2 * A, 0.0, 0.0
    if th <= PI:
        return PI * A / 2 + ramp[0], ramp[1], ramp[2], ramp[3]
    if th <= 5 * PI / 4:
        return 5 * PI * A / 2 - ramp[0], -ramp[1], -ramp[2], -ramp[3]
    if th <= 7 * PI / 4:
        return 15 * PI * A / 4 - 2 * A * th, -2 * A, 0.0, 0.0
    return 2 * PI * A - ramp[0], -ramp[1], -ramp[2], -ramp[3]


def test_paper_profile_matches_the_six_pieces():
    p = paper_program()
    assert p.lift == pytest.approx(3 * PI * A / 2, rel=1e-15)
    th = np.linspace(0, 2 * PI, 2001)[:-1]
    vec = p.evaluate(th)
    scale = (1.0, 1.0, 1.0, 1.0)
    for k, t in enumerate(th):
        ref = paper_pieces(float(t))
        got = p.derivatives(float(t))
        for q in range(4):
            tol = 1e-12 * max(1.0, abs(ref[q]) * 10) * scale[q]
            assert got[q] == pytest.approx(ref[q], abs=tol), (t, q)
            assert vec[q][k] == pytest.approx(ref[q], abs=tol), (t, q)
    assert max(abs(paper_pieces(t)[1]) for t in th) == pytest.approx(2 * A)


def test_scalar_returns_plain_floats_and_is_periodic():
    p = paper_program()
    for th in (0.3, 2.0, 4.0, 5.9):
        ref = p.derivatives(th)
        assert all(type(x) is float for x in ref)
        for n in (-3, -1, 1, 1000):
            np.testing.assert_allclose(p.derivatives(th + n * 2 * PI), ref, rtol=1e-9, atol=1e-12)
    assert p.derivatives(-1e-300) == p.derivatives(0.0)
    assert p.derivatives(-0.5)[0] == pytest.approx(paper_pieces(2 * PI - 0.5)[0], abs=1e-12)


def test_return_is_mirror_and_dwells():
    law = MotionLaw(PRESETS["modified_sine"])
    rl = MotionLaw(PRESETS["cycloidal"])
    h = 0.02
    p = CamProgram(law, rl, h, math.radians(100), math.radians(60), math.radians(120), math.radians(80))
    b1, b2, b3 = math.radians(100), math.radians(160), math.radians(280)
    for frac in (0.1, 0.37, 0.8):
        S, V, Aa, J = law.scalar(frac)
        got = p.derivatives(frac * b1)
        np.testing.assert_allclose(got, (h * S, h * V / b1, h * Aa / b1**2, h * J / b1**3), rtol=1e-13)
        S, V, Aa, J = rl.scalar(frac)
        bd = b3 - b2
        got = p.derivatives(b2 + frac * bd)
        np.testing.assert_allclose(got, (h * (1 - S), -h * V / bd, -h * Aa / bd**2, -h * J / bd**3),
                                   rtol=1e-12, atol=1e-15)
    assert p.derivatives(math.radians(130)) == (h, 0.0, 0.0, 0.0)
    assert p.derivatives(math.radians(300)) == (0.0, 0.0, 0.0, 0.0)
    # finite-difference consistency of s over the full cycle away from breakpoints
    th = np.linspace(0, 2 * PI, 5001)
    bp = np.array(p.breakpoints() + (2 * PI,))
    th = th[np.min(np.abs(th[:, None] - bp[None, :]), axis=1) > 1e-4]
    d = 1e-6
    s_p, ds_p, d2_p, _ = p.evaluate(th + d)
    s_m, ds_m, d2_m, _ = p.evaluate(th - d)
    _, ds, d2, d3 = p.evaluate(th)
    np.testing.assert_allclose((s_p - s_m) / (2 * d), ds, atol=1e-8)
    np.testing.assert_allclose((ds_p - ds_m) / (2 * d), d2, atol=1e-7)
    np.testing.assert_allclose((d2_p - d2_m) / (2 * d), d3, atol=1e-5)


def test_scalar_and_vector_agree_at_breakpoints():
    p = CamProgram("simple_harmonic", "constant_acceleration", 0.01, 2.0, 1.0, 2.0, 2 * PI - 5.0)
    th = np.array(p.breakpoints() + (2 * PI, -2.0, 7.5, 1e6))
    vec = p.evaluate(th)
    for k, t in enumerate(th):
        np.testing.assert_allclose(p.derivatives(float(t)), [q[k] for q in vec], rtol=1e-12, atol=1e-15)


def test_breakpoints():
    p = paper_program()
    expected = [PI * t for t in (0, 1 / 8, 1 / 4, 3 / 4, 7 / 8, 1)] + \
               [PI + PI * t for t in (1 / 8, 1 / 4, 3 / 4, 7 / 8)]
    np.testing.assert_allclose(p.breakpoints(), expected, atol=1e-15)
    q = CamProgram("cycloidal", "paper", 0.01, 1.0, 0.5, 2.0, 2 * PI - 3.5)
    bp = q.breakpoints()
    assert list(bp) == sorted(bp) and 0.0 in bp and 1.0 in bp and 1.5 in bp and 3.5 in bp
    assert all(0 <= b < 2 * PI for b in bp) and len(set(bp)) == len(bp)


@pytest.mark.parametrize("kwargs, fragment", [
    (dict(rise_angle=PI, upper_dwell=0.1, return_angle=PI, lower_dwell=0.0), "2\\*pi"),
    (dict(rise_angle=0.0, upper_dwell=PI, return_angle=PI, lower_dwell=0.0), "rise_angle=0.0"),
    (dict(rise_angle=PI, upper_dwell=-0.1, return_angle=PI, lower_dwell=0.1), "upper_dwell=-0.1"),
    (dict(rise_angle=float("nan"), upper_dwell=0, return_angle=PI, lower_dwell=PI), "rise_angle=nan"),
])
def test_invalid_cycle(kwargs, fragment):
    with pytest.raises(ValueError, match=fragment):
        CamProgram("paper", "paper", 0.1, **kwargs)


def test_invalid_law_and_lift():
    with pytest.raises(ValueError, match="known presets"):
        CamProgram("nope", "paper", 0.1, PI, 0, PI, 0)
    with pytest.raises(ValueError, match="return law.*T3=0.2 > T4=0.1"):
        CamProgram("paper", (0.1, 0.1, 0.2, 0.1, 0.5, 0.6), 0.1, PI, 0, PI, 0)
    with pytest.raises(ValueError, match="lift"):
        CamProgram("paper", "paper", 0.0, PI, 0, PI, 0)


def test_pressure_angle():
    p = paper_program()
    rb = 0.1
    for th in (0.2, 1.0, 3.5, 5.0):
        s, ds, _, _ = paper_pieces(th)
        assert p.pressure_angle(th, rb) == pytest.approx(math.atan(ds / (rb + s)), abs=1e-14)
    th = np.linspace(0, 2 * PI, 200001)
    brute = np.abs([math.atan(paper_pieces(t)[1] / (rb + paper_pieces(t)[0])) for t in th[::10]])
    amax, where = p.max_pressure_angle(rb)
    assert amax == pytest.approx(brute.max(), rel=1e-6) and amax >= brute.max() - 1e-15
    assert abs(p.pressure_angle(where, rb)) == pytest.approx(amax, rel=1e-14)
    assert math.degrees(amax) < 30.0      # docs/model.md section 3: r = 0.1 m keeps it under 30 deg
    with pytest.raises(ValueError):
        p.pressure_angle(0.1, 0.0)
