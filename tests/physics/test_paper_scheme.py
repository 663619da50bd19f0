"""The paper's discrete algorithm (section 3, steps 1-9) checked by hand.

Three steps from rest with u = 3.5 V, T = 1e-3 s, horizontal mounting, L = 0,
recomputed here from the printed steps (with the corrections of docs/model.md) and
compared with PaperScheme to 1e-12 relative (measured: agreement to round-off),
with absolute floors for s, v, a, M: the motion-law code evaluates
x - sin(x) near a segment start with cancellation (s(3.4e-4 rad) is off by 1e-21 m, s' likewise through 1 - cos,
2.8e-10 relative; this file's closed form uses the series), which the backward
differences amplify by 1/T^2 = 1e6 into a: 1e-15 m/s2, harmless.
Nothing from cam_fmu is called for the expected values: the profile is the
paper's closed form and step 2's RK4 on the linear eq. (12) is written as its
exact polynomial: omega_1 = omega_inf + (omega_0 - omega_inf) P4(-lambda T).
"""
from __future__ import annotations

import math

import pytest

from cam_fmu.physics.drive import DriveModel
from cam_fmu.physics.formulations.paper import PaperScheme
from cam_fmu.fmu.engine import DriveSimulator
from test_drive_closed_form import DEFAULTS, paper_profile, sgn

R, C_E, C_M, J_M, M_F, MASS, G, MU, R_B = (DEFAULTS[k] for k in ("R", "c_e", "c_m", "J_m", "M_f", "m", "G", "mu", "r_b"))
U, T = 3.5, 1e-3
FLOOR = dict(s=1e-19, v=1e-16, a=1e-13, M=1e-15, alpha=1e-16)  # m, m/s, m/s2, N m: see the module docstring


def _rk4_linear(omega: float, M: float, J: float) -> float:
    """RK4 of omega_dot = (c_m u - R M - c_e c_m omega) / (R J) over T: exact Taylor polynomial of degree 4."""
    lam = C_E * C_M / (R * J)
    w_inf = (C_M * U - R * M) / (C_E * C_M)
    x = -lam * T
    return w_inf + (omega - w_inf) * (1 + x + x * x / 2 + x ** 3 / 6 + x ** 4 / 24)


def _hand_steps(n: int):
    """Steps 1-8 of the paper, by hand, horizontal (gamma = pi, beta = 0)."""
    gamma, beta = math.pi, 0.0
    F_gx = G * math.sin(gamma) * math.cos(beta)  # 4.9e-16 N: the float pi
    G_y = G * math.sin(gamma) * math.sin(beta)
    # Step 1: initial values.
    theta, omega, J, M, M_l = 0.0, 0.0, J_M, M_F, 0.0
    s, v, a = paper_profile(0.0)[0], 0.0, 0.0
    out = []
    for _ in range(n):
        # Stiction (not in the paper): from rest the shaft starts if |c_m u / R - M_l| > M_f.
        if omega == 0.0:
            assert abs(C_M * U / R - M_l) > M_F
            M = M_F * sgn(C_M * U / R - M_l) + M_l
        # Step 2: RK4 on eq. (12), M and J frozen.
        omega = _rk4_linear(omega, M, J)
        i = (U - C_E * omega) / R
        # Step 3: theta by summation of omega.
        theta = theta + omega * T
        # Step 4: s from the profile (c = 0: no backlash).
        s_new, s1, _ = paper_profile(theta)
        # Steps 5-6: backward differences.
        v_new = (s_new - s) / T
        a = (v_new - v) / T
        v, s = v_new, s_new
        # Step 7: eq. (1) with its mu restored, eq. (3); v > 0 on the rise.
        tan_a = s1 / (R_B + s_new)
        f = MU * ((MASS * a - F_gx) * tan_a + G_y - G * math.cos(gamma)) / (1 - MU * tan_a)
        assert (MASS * a + f - F_gx) * tan_a + G_y >= 0  # eq. (1)'s branch holds
        M_l = (MASS * a + f - F_gx) * s1
        # Step 8: eq. (4), and M for the next step.
        J = J_M + MASS * s1 * s1
        M = M_F * sgn(omega) + M_l
        out.append(dict(theta=theta, omega=omega, i=i, s=s, v=v, a=a, M=M, J=J, alpha=math.atan(tan_a)))
    return out


def test_three_steps_from_rest_by_hand():
    scheme = PaperScheme(DriveModel(dict(formulation="paper")), 0.0, 0.0, 0.0)
    expected = _hand_steps(3)
    for k, row in enumerate(expected):
        scheme.step(T, U)
        got = scheme.outputs()
        for name, value in row.items():
            assert got[name] == pytest.approx(value, rel=1e-12, abs=FLOOR.get(name, 0.0)), (k, name)
    # The numbers are not trivial: the cam moved and the follower loads the shaft.
    assert expected[-1]["omega"] > 0.5 and expected[-1]["s"] > 0 and expected[-1]["M"] > M_F


def test_first_step_values_in_numbers():
    """Step 2 from rest, in numbers: lambda = c_e c_m / (R J_m) = 25.63 1/s,
    omega_inf = (c_m u - R M_f) / (c_e c_m) = 13.35 rad/s, omega_1 = omega_inf (1 - P4(-lambda T)) = 0.3380 rad/s."""
    lam = C_E * C_M / (R * J_M)
    w_inf = (C_M * U - R * M_F) / (C_E * C_M)
    assert lam == pytest.approx(25.63, abs=0.01)
    assert w_inf == pytest.approx(13.35, abs=0.01)
    x = lam * T
    w1 = w_inf * (x - x * x / 2 + x ** 3 / 6 - x ** 4 / 24)
    assert w1 == pytest.approx(0.3380, abs=1e-4)
    scheme = PaperScheme(DriveModel(dict(formulation="paper")), 0.0, 0.0, 0.0)
    scheme.step(T, U)
    assert scheme.omega == pytest.approx(w1, rel=1e-13)


def test_simulator_paper_formulation_runs_the_same_steps():
    """DriveSimulator(formulation='paper') with h_max = T takes exactly these steps."""
    sim = DriveSimulator(dict(formulation="paper", h_max=T))
    expected = _hand_steps(3)
    for k in range(3):
        sim.do_step(k * T, T, U, 1.0)
        out = sim.outputs()
        for name in ("theta", "omega", "M", "J", "s"):
            assert out[name] == pytest.approx(expected[k][name], rel=1e-12, abs=FLOOR.get(name, 0.0)), (k, name)
