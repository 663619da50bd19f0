"""The DC motor: its equations written once (SI units, ``math`` only).

Armature: L di/dt = u - R i - c_e omega; torque c_m i. With L = 0 the current
is quasi-static, i = (u - c_e omega) / R (the paper neglects L).
"""
from __future__ import annotations

import math
from dataclasses import dataclass


@dataclass(frozen=True)
class Motor:
    """R [Ohm], L [H] (0: neglected), c_e [V/(rad/s)], c_m [N m/A]."""

    R: float
    L: float
    c_e: float
    c_m: float

    def quasi_static_current(self, u: float, omega: float) -> float:
        """i [A] with L = 0 (or the value L > 0 relaxes to): (u - c_e omega) / R."""
        return (u - self.c_e * omega) / self.R

    def quasi_static_torque(self, u: float, omega: float) -> float:
        """c_m i [N m] with the quasi-static current: c_m (u - c_e omega) / R."""
        return self.c_m * (u - self.c_e * omega) / self.R

    def current_rate(self, u: float, i: float, omega: float) -> float:
        """di/dt [A/s] with L > 0: (u - R i - c_e omega) / L."""
        return (u - self.R * i - self.c_e * omega) / self.L

    def current_at_rest(self, i: float, u: float, dt: float) -> float:
        """i [A] after dt [s] with the shaft held (omega = 0): exact approach to u / R."""
        target = u / self.R
        return target + (i - target) * math.exp(-dt * self.R / self.L)

    def voltage(self, i: float, omega: float) -> float:
        """u [V] that drives the current i [A] at omega [rad/s] with di/dt = 0."""
        return self.R * i + self.c_e * omega

    def electrical_rate(self, J: float) -> float:
        """Largest rate [1/s] of the motor's own dynamics with inertia J [kg m2].

        L > 0: the pole R/L plus the electromechanical coupling sqrt(c_e c_m / (J L));
        L = 0: the mechanical pole c_e c_m / (R J) of the back-EMF damping.
        """
        if self.L > 0.0:
            return self.R / self.L + math.sqrt(self.c_e * self.c_m / (J * self.L))
        return self.c_e * self.c_m / (self.R * J)
