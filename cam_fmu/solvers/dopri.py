"""Dormand-Prince 5(4): one step with its error estimate (``math`` only)."""
from __future__ import annotations

import math

from .base import Derivative, StepRejected, Stepper, Vector

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


_TWO_PI = 2.0 * math.pi


class DormandPrince45(Stepper):
    """Adaptive Dormand-Prince 5(4) with error control (rtol, atol); h_max caps its step."""

    name = "rk45"
    adaptive = True

    def step(self, f, y, dt, system, u, mode):
        return dopri_step(f, y, dt)[0]

    def attempt(self, f: Derivative, y: Vector, remaining: float, k1: tuple | None, time: float,
                caps: tuple[float, ...], span: float) -> tuple[float, list[float], tuple]:
        """One accepted step: (dt [s], y_new, f(y_new)); raises SimulationError below the smallest step.

        The smallest step is 1e-12 of ``span``, the communication step [s]: relative to the
        step's own time scale, never to the absolute time (a master may start at t = 1.7e9 s).

        ``caps[k]`` bounds the magnitude that scales slot k's error: theta grows
        without bound but enters the physics mod 2 pi, so its error is scaled by
        at most 2 pi and its accuracy does not decay over many turns (scaled by
        |theta|, rk45 lost 1e-4 rad within 1 s at 100 V, ~100 turns).
        """
        dt = min(self.h_next, remaining, self.h_max)
        floor = 1e-12 * span
        atol, rtol = self.atol, self.rtol
        while True:
            y5, err, k7 = dopri_step(f, y, dt, k1)
            total = 0.0
            for e, a, b, cap in zip(err, y, y5, caps):
                total += (e / (atol + rtol * min(max(abs(a), abs(b)), cap))) ** 2
            norm = math.sqrt(total / len(y))
            if norm <= 1.0:
                factor = 5.0 if norm == 0.0 else min(5.0, 0.9 * norm ** -0.2)
                if dt < remaining or factor < 1.0:
                    self.h_next = min(dt * factor, 1e3)
                else:
                    self.h_next = max(self.h_next, dt * min(factor, 1.0))
                return dt, y5, k7
            if not math.isfinite(norm):
                norm = 1e10
            dt *= max(0.1, 0.9 * norm ** -0.2)
            if dt < floor:
                raise StepRejected(
                    f"solver 'rk45' cannot meet rtol = {rtol:g}, atol = {atol:g}: its step fell "
                    f"below {floor:g} s (1e-12 of the communication step) at t = {time:g} s: loosen rtol/atol, "
                    "or check the inputs and parameters for a near-singular drive")
