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


def phi_functions(z: float) -> tuple[float, float, float, float]:
    """(e^z, phi1, phi2, phi3) with phi_k(z) = sum_n z^n / (n + k)!, stable near 0."""
    if abs(z) < 0.5:
        p1 = p2 = p3 = 0.0
        term = 1.0  # z^n / n!
        for n in range(25):
            p1 += term / (n + 1)
            p2 += term / ((n + 1) * (n + 2))
            p3 += term / ((n + 1) * (n + 2) * (n + 3))
            term *= z / (n + 1)
        return math.exp(z), p1, p2, p3
    ez = math.exp(z)
    p1 = (ez - 1.0) / z
    p2 = (ez - 1.0 - z) / (z * z)
    p3 = (ez - 1.0 - z - 0.5 * z * z) / (z * z * z)
    return ez, p1, p2, p3


class EtdCoefficients:
    """Cox-Matthews ETDRK4 weights for a diagonal linear part c [1/s] and step h [s]."""

    def __init__(self, rates: Sequence[float], h: float) -> None:
        self.h = h
        self.rates = tuple(rates)
        self.e_half, self.phi_half, self.e_full, self.f1, self.f2, self.f3 = [], [], [], [], [], []
        for c in self.rates:
            eh, p1h, _, _ = phi_functions(0.5 * c * h)
            ez, p1, p2, p3 = phi_functions(c * h)
            self.e_half.append(eh)
            self.phi_half.append(p1h)
            self.e_full.append(ez)
            self.f1.append(p1 - 3.0 * p2 + 4.0 * p3)
            self.f2.append(p2 - 2.0 * p3)
            self.f3.append(-p2 + 4.0 * p3)


def etdrk4_step(f: Derivative, y: Vector, coef: EtdCoefficients) -> list[float]:
    """Exponential RK4 (Cox and Matthews 2002): the linear part c y is exact.

    ``f`` is the full derivative; the nonlinear part is N(y) = f(y) - c y.
    With every rate 0 this is the classical RK4.
    """
    h, rates = coef.h, coef.rates
    hh = 0.5 * h

    def nonlinear(v):
        return [d - c * x for d, c, x in zip(f(v), rates, v)]

    n_y = nonlinear(y)
    a = [eh * x + hh * p * n for eh, p, x, n in zip(coef.e_half, coef.phi_half, y, n_y)]
    n_a = nonlinear(a)
    b = [eh * x + hh * p * n for eh, p, x, n in zip(coef.e_half, coef.phi_half, y, n_a)]
    n_b = nonlinear(b)
    cc = [eh * x + hh * p * (2.0 * nb - ny) for eh, p, x, nb, ny in zip(coef.e_half, coef.phi_half, a, n_b, n_y)]
    n_c = nonlinear(cc)
    return [
        e * x + h * (w1 * ny + 2.0 * w2 * (na + nb) + w3 * nc)
        for e, w1, w2, w3, x, ny, na, nb, nc in zip(
            coef.e_full, coef.f1, coef.f2, coef.f3, y, n_y, n_a, n_b, n_c)
    ]
