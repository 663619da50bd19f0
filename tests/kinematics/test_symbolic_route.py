"""The blog post's own symbolic route (sympy; docs/model.md section 1) against the closed-form solve.

The blog post builds A, V, S per segment with sympy (A = Amp sin P_i on segments 1
and 3, Amm sin P_i on 5 and 7, P_i = (T - T_{i-1})/F_i + (i-1) pi/4, V and S by
indefinite integration plus constants C_i, B_i) and announces, but never shows,
the boundary-value solve.  We finish it: S(0) = V(0) = 0, S(1) = 1, V(1) = 0,
continuity of V and S at T1..T6 -> 16 linear equations in Amp, Amm, C1..C7,
B1..B7, solved by sympy for one asymmetric case with all segments non-empty
(the symbolic route divides by F_i, so it cannot do zero-length ones).
"""

import pytest
import sympy
from sympy import Rational as R, integrate, pi, sin, symbols

from cam_fmu.kinematics.motion_law import MotionLaw

T_CASE = (R(1, 10), R(1, 5), R(7, 20), R(1, 2), R(3, 5), R(9, 10))


def seed_route(Tvals):
    T, Amp, Amm = symbols("T Amp Amm")
    C = symbols("C1:8")
    B = symbols("B1:8")
    T_list = [0, *Tvals, 1]
    A_list, V_list, S_list = [], [], []
    for i in range(1, 8):
        F = (T_list[i] - T_list[i - 1]) / (pi / 2)
        P = (T - T_list[i - 1]) / F + (i - 1) * (pi / 4)
        if i in (1, 3):
            A = Amp * sin(P)
        elif i == 2:
            A = Amp
        elif i == 4:
            A = 0
        elif i in (5, 7):
            A = Amm * sin(P)
        else:
            A = -Amm
        V = integrate(A, T) + C[i - 1]
        S = integrate(V, T) + B[i - 1]
        A_list.append(A)
        V_list.append(V)
        S_list.append(S)
    eqs = [V_list[0].subs(T, 0), S_list[0].subs(T, 0),
           V_list[6].subs(T, 1), S_list[6].subs(T, 1) - 1]
    for i in range(1, 7):
        eqs.append(V_list[i - 1].subs(T, T_list[i]) - V_list[i].subs(T, T_list[i]))
        eqs.append(S_list[i - 1].subs(T, T_list[i]) - S_list[i].subs(T, T_list[i]))
    unknowns = [Amp, Amm, *C, *B]
    M, rhs = sympy.linear_eq_to_matrix(eqs, unknowns)
    sol = M.evalf(30).LUsolve(rhs.evalf(30))
    values = dict(zip(unknowns, sol))
    return T, T_list, V_list, S_list, C, B, values


def test_seed_symbolic_route_matches_closed_form():
    T, T_list, V_list, S_list, C, B, sol = seed_route(T_CASE)
    Amp_s, Amm_s = float(sol[symbols("Amp")]), float(sol[symbols("Amm")])
    m = MotionLaw(tuple(float(t) for t in T_CASE))
    assert abs(Amp_s - Amm_s) > 0.5            # really asymmetric
    assert m.Amp == pytest.approx(Amp_s, rel=1e-13)
    assert m.Amm == pytest.approx(Amm_s, rel=1e-13)

    # The 14 constants: the blog post's C_i, B_i (global-T antiderivatives) follow
    # from ours (V0_i, S0_i at each segment start) by C_i = V0_i - V_i|C=0 (T_{i-1}),
    # B_i = S0_i - S_i|B=0 (T_{i-1}).
    V0, S0 = m.constants()
    Amp, Amm = symbols("Amp Amm")
    amps = {Amp: sol[Amp], Amm: sol[Amm]}
    for i in range(7):
        t0 = T_list[i]
        V_noC = V_list[i].subs(C[i], 0).subs(amps).subs(T, t0)
        C_ours = V0[i] - float(V_noC)
        assert C_ours == pytest.approx(float(sol[C[i]]), abs=1e-12), f"C{i + 1}"
        S_noB = S_list[i].subs(B[i], 0).subs(C[i], sol[C[i]]).subs(amps).subs(T, t0)
        B_ours = S0[i] - float(S_noB)
        assert B_ours == pytest.approx(float(sol[B[i]]), abs=1e-12), f"B{i + 1}"

    # And the solved symbolic curve equals ours everywhere.
    for i in range(7):
        a, b = float(T_list[i]), float(T_list[i + 1])
        for frac in (0.1, 0.5, 0.9):
            t = a + frac * (b - a)
            Vs = float(V_list[i].subs(sol).subs(T, t))
            Ss = float(S_list[i].subs(sol).subs(T, t))
            S, V, _, _ = m.scalar(t)
            assert V == pytest.approx(Vs, abs=1e-12)
            assert S == pytest.approx(Ss, abs=1e-12)
