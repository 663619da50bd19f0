"""The angle of an oscillating follower's arm from a cam program: psi(theta) = lift_angle * S(theta).

S = s / h is the program's normalised lift (h = ``program.lift``, the largest lift; a motion table is
normalised by its largest row), so psi runs from 0 to lift_angle [rad] and its derivatives over the cam
angle are psi^(k) = lift_angle * s^(k) / h.  Units: rad; numpy arrays or floats as the program gives them.
"""

from __future__ import annotations

import math

import numpy as np

__all__ = ["ArmMotion"]


class ArmMotion:
    """psi, psi', psi'', psi''' [rad, rad/rad^k] of a program scaled to `lift_angle` [rad], 0 < lift_angle < pi."""

    def __init__(self, program, lift_angle: float) -> None:
        a = float(lift_angle)
        if not (math.isfinite(a) and 0.0 < a < math.pi):
            raise ValueError(f"lift_angle must lie in (0, 180) deg, got {math.degrees(a)!r} deg")
        h = float(program.lift)
        if not (math.isfinite(h) and h > 0.0):
            raise ValueError(f"the cam program's lift must be > 0 to normalise it, got {h!r} m")
        self.program = program
        self.lift_angle = a
        self._k = a / h

    def derivatives(self, theta):
        """(psi, psi', psi'', psi''') at theta [rad]: floats for a scalar theta, arrays otherwise."""
        if np.ndim(theta) == 0:
            return tuple(self._k * float(q) for q in self.program.derivatives(float(theta)))
        return tuple(self._k * q for q in self.program.evaluate(np.asarray(theta, dtype=float)))
