"""Polynomial rise laws S(T) = sum_k c_k T^k on [0, 1], dimensionless (the 3-4-5 and 4-5-6-7 polynomials).

    3-4-5:    S = 10 T^3 - 15 T^4 + 6 T^5                  (S, V, A continuous; J jumps at the ends)
    4-5-6-7:  S = 35 T^4 - 84 T^5 + 70 T^6 - 20 T^7        (S, V, A, J continuous)

Both rise from S(0) = 0 to S(1) = 1 with V = A = 0 at both ends (and J = 0 for 4-5-6-7), the conditions that
fix their coefficients. Outside [0, 1] the law continues as dwells, as ``MotionLaw`` does: (0, 0, 0, 0) for
T < 0 and (1, 0, 0, 0) for T > 1. ``math`` and numpy only. The C engine does not evaluate these laws yet: the
drive's ``rise_law`` takes the harmonic-trapezoid presets (``presets.PRESETS``) only.
"""

from __future__ import annotations

import math
from typing import Sequence

import numpy as np

__all__ = ["PolynomialLaw"]


class PolynomialLaw:
    """A rise law S(T) = sum_k coef[k] T^k on [0, 1]; immutable, evaluated like ``MotionLaw``."""

    __slots__ = ("coef", "_d1", "_d2", "_d3")

    def __init__(self, coef: Sequence[float]) -> None:
        c = tuple(float(x) for x in coef)
        if not c or not all(math.isfinite(x) for x in c):
            raise ValueError(f"polynomial coefficients must be finite numbers, got {coef!r}")
        if abs(sum(c) - 1.0) > 1e-12 or abs(c[0]) > 0.0:
            raise ValueError(f"a rise polynomial needs S(0) = 0 and S(1) = 1, got coefficients {c!r}")
        d1 = tuple(k * c[k] for k in range(1, len(c)))
        d2 = tuple(k * d1[k] for k in range(1, len(d1)))
        d3 = tuple(k * d2[k] for k in range(1, len(d2)))
        for name, value in (("coef", c), ("_d1", d1), ("_d2", d2), ("_d3", d3)):
            object.__setattr__(self, name, value)

    def __setattr__(self, name, value):
        raise AttributeError(f"PolynomialLaw is immutable (tried to set {name!r})")

    def __eq__(self, other):
        return isinstance(other, PolynomialLaw) and other.coef == self.coef

    def __hash__(self):
        return hash(("PolynomialLaw", self.coef))

    def __repr__(self):
        return f"PolynomialLaw(coef={self.coef!r})"

    @staticmethod
    def _horner(c: tuple[float, ...], x):
        out = 0.0 * x
        for a in reversed(c):
            out = out * x + a
        return out

    def scalar(self, T: float) -> tuple[float, float, float, float]:
        """(S, V, A, J) at one T; the dwells outside [0, 1]; at T = 0 and 1 the values inside."""
        if T < 0.0:
            return 0.0, 0.0, 0.0, 0.0
        if T > 1.0:
            return 1.0, 0.0, 0.0, 0.0
        return tuple(float(self._horner(c, T)) for c in (self.coef, self._d1, self._d2, self._d3))  # type: ignore

    def evaluate(self, T: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """(S, V, A, J) over an array of T; same conventions as :meth:`scalar`."""
        T = np.asarray(T, dtype=float)
        inside = (T >= 0.0) & (T <= 1.0)
        x = np.clip(T, 0.0, 1.0)
        S = np.where(T > 1.0, 1.0, np.where(inside, self._horner(self.coef, x), 0.0))
        V, A, J = (np.where(inside, self._horner(c, x), 0.0) for c in (self._d1, self._d2, self._d3))
        return S, V, A, J

    def jumps(self) -> tuple[float, ...]:
        """T in [0, 1] where A jumps: none (A = 0 at both ends of these rises)."""
        ends = (self._horner(self._d2, 0.0), self._horner(self._d2, 1.0))
        return tuple(t for t, a in zip((0.0, 1.0), ends) if abs(a) > 1e-12)

    def breakpoints(self) -> tuple[float, ...]:
        """T where a derivative of the law may be discontinuous: the ends."""
        return (0.0, 1.0)
