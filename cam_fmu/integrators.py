"""One-step methods on short tuples of floats (``math`` only: the FMU's hot path).

``f(y)`` returns dy/dt as a tuple; y is a list or tuple of floats. Each
function advances by one step h [s] and returns the new state as a list.
"""
from __future__ import annotations

import math
from typing import Callable, Sequence

Vector = Sequence[float]
Derivative = Callable[[Vector], tuple]


def euler_step(f: Derivative, y: Vector, h: float) -> list[float]:
    """Explicit Euler, order 1."""
    return [a + h * b for a, b in zip(y, f(y))]


def rk4_step(f: Derivative, y: Vector, h: float) -> list[float]:
    """Classical Runge-Kutta, order 4."""
    k1 = f(y)
    k2 = f([a + 0.5 * h * b for a, b in zip(y, k1)])
    k3 = f([a + 0.5 * h * b for a, b in zip(y, k2)])
    k4 = f([a + h * b for a, b in zip(y, k3)])
    h6 = h / 6.0
    return [a + h6 * (b1 + 2.0 * b2 + 2.0 * b3 + b4) for a, b1, b2, b3, b4 in zip(y, k1, k2, k3, k4)]


# Dormand-Prince 5(4) tableau (Hairer, Norsett, Wanner, Solving ODE I, table 5.2).
_C = (0.0, 1 / 5, 3 / 10, 4 / 5, 8 / 9, 1.0, 1.0)
_A = (
    (),
    (1 / 5,),
    (3 / 40, 9 / 40),
    (44 / 45, -56 / 15, 32 / 9),
    (19372 / 6561, -25360 / 2187, 64448 / 6561, -212 / 729),
    (9017 / 3168, -355 / 33, 46732 / 5247, 49 / 176, -5103 / 18656),
    (35 / 384, 0.0, 500 / 1113, 125 / 192, -2187 / 6784, 11 / 84),
)
_E = (71 / 57600, 0.0, -71 / 16695, 71 / 1920, -17253 / 339200, 22 / 525, -1 / 40)  # b5 - b4


def dopri_step(f: Derivative, y: Vector, h: float, k1: tuple | None = None) -> tuple[list[float], list[float], tuple]:
    """Dormand-Prince 5(4): (y5, error estimate y5 - y4, f(y5) for FSAL reuse).

    Unrolled over the tableau: this is the FMU's hot path.
    """
    a2, a3, a4, a5, a6, b = _A[1:]
    if k1 is None:
        k1 = f(y)
    k2 = f([x + h * a2[0] * p1 for x, p1 in zip(y, k1)])
    k3 = f([x + h * (a3[0] * p1 + a3[1] * p2) for x, p1, p2 in zip(y, k1, k2)])
    k4 = f([x + h * (a4[0] * p1 + a4[1] * p2 + a4[2] * p3) for x, p1, p2, p3 in zip(y, k1, k2, k3)])
    k5 = f([x + h * (a5[0] * p1 + a5[1] * p2 + a5[2] * p3 + a5[3] * p4)
            for x, p1, p2, p3, p4 in zip(y, k1, k2, k3, k4)])
    k6 = f([x + h * (a6[0] * p1 + a6[1] * p2 + a6[2] * p3 + a6[3] * p4 + a6[4] * p5)
            for x, p1, p2, p3, p4, p5 in zip(y, k1, k2, k3, k4, k5)])
    # b[1] is 0; the seventh stage is evaluated at y5 itself (first same as last).
    y5 = [x + h * (b[0] * p1 + b[2] * p3 + b[3] * p4 + b[4] * p5 + b[5] * p6)
          for x, p1, p3, p4, p5, p6 in zip(y, k1, k3, k4, k5, k6)]
    k7 = f(y5)
    e = _E
    err = [h * (e[0] * p1 + e[2] * p3 + e[3] * p4 + e[4] * p5 + e[5] * p6 + e[6] * p7)
           for p1, p3, p4, p5, p6, p7 in zip(k1, k3, k4, k5, k6, k7)]
    return y5, err, k7


def phi_functions(z: float) -> tuple[float, float, float, float, float]:
    """(e^z, phi1, phi2, phi3, phi4) with phi_k(z) = sum_n z^n / (n + k)!, stable near 0."""
    if abs(z) < 1.0:
        p = [0.0, 0.0, 0.0, 0.0]
        term = 1.0  # z^n / n!
        for n in range(30):
            denom = 1.0
            for k in range(4):
                denom *= n + k + 1
                p[k] += term / denom
            term *= z / (n + 1)
        return (math.exp(z), *p)
    ez = math.exp(z)
    p1 = (ez - 1.0) / z
    p2 = (p1 - 1.0) / z
    p3 = (p2 - 0.5) / z
    p4 = (p3 - 1.0 / 6.0) / z
    return ez, p1, p2, p3, p4


class MotorEtdCoefficients:
    """ETDRK4 weights for the motor's linear part on (omega, e) and step h [s].

    The linear part is [[0, a], [0, c]]: e is the current's deviation from its
    quasi-static value, c = -R/L [1/s] its decay rate and a = c_m / J [1/(A s2)]
    its torque on omega (a changes every step, c and h do not). A function F
    of h[[0, a], [0, c]] is [[F(0), a h (F(ch) - F(0)) / (ch)], [0, F(ch)]];
    the divided differences of phi_k are phi_(k+1).
    """

    def __init__(self, c: float, h: float) -> None:
        self.h = h
        self.c = c
        ez, p1, p2, p3, p4 = phi_functions(c * h)
        eh, q1, q2, _, _ = phi_functions(0.5 * c * h)
        self.e_full, self.e_half = ez, eh
        self.dd_e_full, self.dd_e_half = p1, q1  # divided differences of exp
        self.phi_half, self.dd_phi_half = q1, q2
        self.f = (p1 - 3.0 * p2 + 4.0 * p3, p2 - 2.0 * p3, -p2 + 4.0 * p3)
        self.dd_f = (p2 - 3.0 * p3 + 4.0 * p4, p3 - 2.0 * p4, -p3 + 4.0 * p4)


def etdrk4_motor_step(f: Derivative, y: Vector, coef: MotorEtdCoefficients, a: float) -> list[float]:
    """Exponential RK4 (Cox and Matthews 2002) on (theta, omega, e).

    The linear part [[0, a], [0, c]] on (omega, e) is integrated exactly, so the
    electrical pole c = -R/L and the torque of the decaying current transient
    on omega stay exact at any step; theta is plain RK4.
    """
    h, c = coef.h, coef.c
    hh = 0.5 * h
    a_half = a * hh
    a_full = a * h

    def nonlinear(v):
        d = f(v)
        return (d[0], d[1] - a * v[2], d[2] - c * v[2])

    def half(v, n):  # e^(M/2) v + (h/2) phi1(M/2) n on the block, RK4 stage on theta
        return (
            v[0] + hh * n[0],
            v[1] + a_half * coef.dd_e_half * v[2] + hh * (n[1] + a_half * coef.dd_phi_half * n[2]),
            coef.e_half * v[2] + hh * coef.phi_half * n[2],
        )

    n_y = nonlinear(y)
    st_a = half(y, n_y)
    n_a = nonlinear(st_a)
    st_b = half(y, n_a)
    n_b = nonlinear(st_b)
    st_c = half(st_a, tuple(2.0 * p - q for p, q in zip(n_b, n_y)))
    n_c = nonlinear(st_c)
    (f1, f2, f3), (g1, g2, g3) = coef.f, coef.dd_f
    w = 1.0 / 6.0  # F(0) of f1, f2, f3
    theta = y[0] + h * (w * n_y[0] + 2.0 * w * (n_a[0] + n_b[0]) + w * n_c[0])
    omega = (y[1] + a_full * coef.dd_e_full * y[2]
             + h * (w * n_y[1] + 2.0 * w * (n_a[1] + n_b[1]) + w * n_c[1])
             + h * a_full * (g1 * n_y[2] + 2.0 * g2 * (n_a[2] + n_b[2]) + g3 * n_c[2]))
    e = coef.e_full * y[2] + h * (f1 * n_y[2] + 2.0 * f2 * (n_a[2] + n_b[2]) + f3 * n_c[2])
    return [theta, omega, e]
