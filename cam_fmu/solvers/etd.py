"""Exponential RK4 for the motor's linear part: coefficients and one step (``math`` only)."""
from __future__ import annotations

import math

from .base import Derivative, Stepper, Vector
from .explicit import rk4_step


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


class ETDRK4(Stepper):
    """Exponential RK4: the electrical pole -R/L and its torque on omega integrated exactly.

    ETD runs on the current's deviation e = i - (u - c_e omega) / R from its
    quasi-static value: de/dt = -(R/L) e + (c_e/R) omega_dot, and on e's torque
    c_m e / J on omega. The forcing stays bounded as L -> 0, so the stiff limit
    and the fast transient after a break-away are exact. Measured before: ETD
    on i alone lags the back-EMF by one step (order 1, 2.4e-2 rad at 1 ms with
    L = 1e-6 H) and a diagonal ETD on e still missed the transient's torque
    (7e-3 rad). With no current in the state it is the classical RK4.
    """

    name = "etdrk4"
    stability = 2.5
    resolution = 0.1  # 400 V: 0.07 rad of 266 (was 214 rad off with the stability limit alone)
    promised_relative = 1e-2  # 2.5e-4 measured at 400 V
    exact_electrical_pole = True

    def __init__(self, settings):
        super().__init__(settings)
        self._coef: MotorEtdCoefficients | None = None

    def step(self, f, y, dt, system, u, mode):
        if not system.has_current:
            return rk4_step(f, y, dt)
        motor = system.motor
        R, ce, rate = motor.R, motor.c_e, motor.R / motor.L
        coef = self._coef
        if coef is None or coef.h != dt:
            coef = self._coef = MotorEtdCoefficients(-rate, dt)
        a = system.torque_gain(y, mode)
        qs = motor.quasi_static_current

        def deviation_rate(z):
            i = qs(u, z[1]) + z[2]
            d = f((z[0], z[1], i))
            return (d[0], d[1], -rate * z[2] + ce / R * d[1])

        z = etdrk4_motor_step(deviation_rate, (y[0], y[1], y[2] - qs(u, y[1])), coef, a)
        return [z[0], z[1], z[2] + qs(u, z[1])]
