"""Closed forms shared by the drive tests, written from the paper, not from cam_fmu.

The paper's profile (docs/model.md section 2; the paper's section 2.1), A = 35 mm, in
six pieces over one revolution (rise [0, pi], return [pi, 2 pi]):

    rise,   [0, pi/4]:      s = A (t - sin(4 t) / 4)
            [pi/4, 3pi/4]:  s = 2 A t - pi A / 4
            [3pi/4, pi]:    s = A (t - sin(4 t) / 4) + pi A / 2
    return, phi = t - pi:   s = 3 pi A / 2 - s_rise(phi)

The other drive test files import ``paper_profile``, ``friction_fixed_point``
and ``DEFAULTS`` from here. The tests in this file check these closed forms
against cam_fmu's general harmonic-trapezoid code (the only place the two meet).
"""
from __future__ import annotations

import math

import pytest

A = 0.035  # m
H = 1.5 * math.pi * A  # m, lift

# The project's defaults, written out (docs/model.md section 3), so a
# changed default in parameters.py shows up as a failing test, not a moved oracle.
DEFAULTS = dict(R=19.0, c_e=0.146, c_m=0.015 * 9.80665, J_m=4.41e-5, M_f=0.012, m=0.4, G=4.0,
                mu=0.001, r_b=0.1)


def _x_minus_sin(x: float) -> float:
    """x - sin(x) without cancellation for small x (series to x^15 below 0.5)."""
    if abs(x) >= 0.5:
        return x - math.sin(x)
    total, term, k = 0.0, x, 1
    while k < 15:
        term *= -x * x / ((k + 1) * (k + 2))
        total -= term
        k += 2
    return total


def _rise(t: float) -> tuple[float, float, float]:
    """(s, s', s'') of the rise on [0, pi]."""
    q = math.pi / 4
    if t <= q:
        return A * _x_minus_sin(4 * t) / 4, 2 * A * math.sin(2 * t) ** 2, 4 * A * math.sin(4 * t)
    if t <= 3 * q:
        return 2 * A * t - math.pi * A / 4, 2 * A, 0.0
    return A * (t - math.sin(4 * t) / 4) + math.pi * A / 2, A * (1 - math.cos(4 * t)), 4 * A * math.sin(4 * t)


def paper_profile(theta: float) -> tuple[float, float, float]:
    """(s [m], ds/dtheta [m/rad], d2s/dtheta2 [m/rad2]) of the paper's cam at any theta."""
    t = theta % (2 * math.pi)
    if t <= math.pi:
        return _rise(t)
    s, s1, s2 = _rise(t - math.pi)
    return H - s, -s1, -s2


def friction_fixed_point(n0: float, tan_a: float, sigma: float, mu: float, n_g: float) -> float:
    """Guide friction f from f = mu (|N_r| + |N_g|), N_r = n0 + sigma f tan(alpha), by iteration.

    docs/model.md section 4: N cos(alpha) = m a + sigma f - F_gx, N_r = N sin(alpha) + G_y,
    so N_r = (m a - F_gx) tan(alpha) + G_y + sigma f tan(alpha) = n0 + sigma f tan(alpha).
    A contraction (factor mu |tan alpha| < 1): iterate to a fixed point, a method
    independent of the two-branch solve in physics/drive.py.
    """
    f = 0.0
    for _ in range(200):
        f_new = mu * (abs(n0 + sigma * f * tan_a) + abs(n_g))
        if f_new == f:
            break
        f = f_new
    return f


def sgn(x: float) -> float:
    return 1.0 if x > 0 else (-1.0 if x < 0 else 0.0)


# ------------------------------------------------------------------ tests
def test_closed_form_profile_is_continuous_and_periodic():
    """The six pieces join in s and s' (the closed form itself is right)."""
    eps = 1e-9
    for b in (math.pi / 4, 3 * math.pi / 4, math.pi, 5 * math.pi / 4, 7 * math.pi / 4, 2 * math.pi):
        lo, hi = paper_profile(b - eps), paper_profile(b + eps)
        assert lo[0] == pytest.approx(hi[0], abs=1e-9)
        assert lo[1] == pytest.approx(hi[1], abs=1e-8)
    assert paper_profile(math.pi)[0] == pytest.approx(H, abs=1e-15)
    assert paper_profile(math.pi / 2)[1] == 2 * A  # peak ds/dtheta = 2 A
    x = 0.3
    assert _x_minus_sin(x) == pytest.approx(x - math.sin(x), rel=1e-14)
    assert _x_minus_sin(1e-4) == pytest.approx(1e-12 / 6 - 1e-20 / 120, rel=1e-15)


def test_cam_program_matches_the_paper_profile():
    """The default cam program of DriveModel is the paper's profile (to 1e-13 m)."""
    from cam_fmu.physics.drive import DriveModel

    prog = DriveModel({}).program
    for k in range(1001):
        th = -3.0 + 16.0 * k / 1000  # several turns, negative angles included
        s, s1, s2, _ = prog.derivatives(th)
        e = paper_profile(th)
        assert s == pytest.approx(e[0], abs=1e-13)
        assert s1 == pytest.approx(e[1], abs=1e-13)
        assert s2 == pytest.approx(e[2], abs=1e-12)


def test_defaults_are_the_papers_numbers():
    from cam_fmu.physics.parameters import defaults

    d = defaults()
    for name, value in DEFAULTS.items():
        assert d[name] == pytest.approx(value, rel=1e-15), name
    assert d["L"] == 0.0 and d["c"] == 0.0 and d["gamma"] == math.pi and d["beta"] == 0.0
