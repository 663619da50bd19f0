"""Helpers of the closed-form tests of the cam geometry: a cam program from a sympy expression of the cam
angle (its derivatives by sympy), the fixed frame into the cam frame."""

from __future__ import annotations

import math

import numpy as np
import sympy as sp


class SympyProgram:
    """The program s(th) = expr / scale (th the sympy Symbol in expr): `evaluate`, `derivatives` (s .. s''')
    and `breakpoints` as a cam program has them (derivatives above `order` NaN); ``lift`` = 1 (s is already normalised when scale is the
    largest value of expr, as an oscillating follower's lift_angle is of psi)."""

    def __init__(self, expr, th: sp.Symbol, scale: float = 1.0, order: int = 2) -> None:
        # derivatives up to `order` (the geometry needs s''); above it NaN, so that a use of them shows
        nan = sp.lambdify(th, sp.nan * th, "numpy")
        self._f = [sp.lambdify(th, sp.diff(expr, th, j), "numpy") if j <= order else nan for j in range(4)]
        self.scale = float(scale)
        self.lift = 1.0

    def values(self, theta) -> np.ndarray:
        """expr itself at theta (not scaled)."""
        theta = np.asarray(theta, dtype=float)
        return np.broadcast_to(self._f[0](theta), theta.shape).astype(float)

    def evaluate(self, theta):
        theta = np.asarray(theta, dtype=float)
        return tuple(np.broadcast_to(f(theta), theta.shape).astype(float) / self.scale for f in self._f)

    def derivatives(self, theta):
        return tuple(float(f(theta)) / self.scale for f in self._f)

    def breakpoints(self):
        return (0.0,)

    def largest(self, n: int = 20001) -> float:
        """The largest value of expr on n angles of a turn (the scale of an oscillating follower's S)."""
        return float(self.values(np.linspace(0.0, 2.0 * math.pi, n)).max())


def to_cam_frame(theta, x, y):
    """Rot(-theta) (x, y): a point of the fixed frame in the cam frame at cam angle theta (-theta: back)."""
    c, s = np.cos(theta), np.sin(theta)
    return x * c + y * s, -x * s + y * c


def cycloid_program(theta, rise: float, lift: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(s, s', s'') [m, m/rad, m/rad2] of a cycloidal rise over [0, b), a dwell, the mirrored return over [2 b, 3 b) and
    a dwell (b = rise [rad], each piece b; lift [m]): rise lift (x - sin(2 pi x) / (2 pi)), x the fraction of the
    piece, written from the closed form."""
    theta = np.mod(np.asarray(theta, dtype=float), 2.0 * math.pi)
    b, h = rise, lift
    s, s1, s2 = np.zeros_like(theta), np.zeros_like(theta), np.zeros_like(theta)
    up, top, ret = theta < b, (theta >= b) & (theta < 2 * b), (theta >= 2 * b) & (theta < 3 * b)
    x = theta[up] / b
    s[up] = h * (x - np.sin(2 * math.pi * x) / (2 * math.pi))
    s1[up] = h / b * (1.0 - np.cos(2 * math.pi * x))
    s2[up] = 2 * math.pi * h / b ** 2 * np.sin(2 * math.pi * x)
    s[top] = h
    x = (theta[ret] - 2 * b) / b
    s[ret] = h - h * (x - np.sin(2 * math.pi * x) / (2 * math.pi))
    s1[ret] = -h / b * (1.0 - np.cos(2 * math.pi * x))
    s2[ret] = -2 * math.pi * h / b ** 2 * np.sin(2 * math.pi * x)
    return s, s1, s2
