"""A user motion table (cam angle, lift) as a periodic cubic-spline cam program.

The table is CSV text: a header line, then rows ``angle_deg, lift_mm`` (comma,
semicolon, tab or blanks between the two numbers; ``#`` starts a comment
line).  Angles lie in [0, 360] and increase strictly; the motion repeats every
360 deg, so a last row at first angle + 360 deg is allowed only with the first
row's lift (it closes the table and is dropped).  Lifts are >= 0 mm, measured
from the prime circle (see docs/cam_design.md).

Interpolation: the periodic cubic spline through the points (the knots), with
period 2 pi.  Continuity: s, ds/dtheta and d2s/dtheta2 are continuous
everywhere, including across 360 -> 0 deg; d3s/dtheta3 is piecewise constant
and jumps at the knots, which ``breakpoints()`` returns so that the drive's
solvers stop there.  For a table sampled every h rad from a smooth motion the
errors are O(h^4) in s, O(h^3) in s', O(h^2) in s'' (tests/test_motion_table.py
measures them).  Between knots the spline may over- or undershoot the table
(e.g. slightly below 0 next to a dwell at lift 0).

Convention at a knot: the piece *ending* there is used (left limit); only s'''
differs between the sides.

Construction uses numpy; evaluation by ``derivatives`` is ``math`` and
``bisect`` only (the FMU's run-time path), ``evaluate`` is its numpy twin.
"""

from __future__ import annotations

import bisect
import math
import re
from pathlib import Path
from typing import Sequence

import numpy as np

from .cam_program import ProgramBase

__all__ = ["TableProgram", "parse_motion_table", "program_from_table_text", "read_motion_table"]

TWO_PI = 2.0 * math.pi
_SPLIT = re.compile(r"[,;\s]+")


def _solve_cyclic(sub: np.ndarray, diag: np.ndarray, sup: np.ndarray, rhs: np.ndarray) -> np.ndarray:
    """Solve the cyclic tridiagonal system (row i: sub[i] x[i-1] + diag[i] x[i]
    + sup[i] x[i+1] = rhs[i], indices mod n, n >= 3) by Sherman-Morrison and
    the Thomas algorithm; the spline's matrix is strictly diagonally dominant."""
    n = len(diag)
    alpha, beta = sup[-1], sub[0]          # corner entries A[n-1, 0] and A[0, n-1]
    gamma = -diag[0]
    d = diag.astype(float).copy()
    d[0] -= gamma
    d[-1] -= alpha * beta / gamma

    def thomas(r: np.ndarray) -> np.ndarray:
        c = np.empty(n)
        x = np.empty(n)
        c[0] = sup[0] / d[0]
        x[0] = r[0] / d[0]
        for i in range(1, n):
            m = d[i] - sub[i] * c[i - 1]
            c[i] = sup[i] / m if i < n - 1 else 0.0
            x[i] = (r[i] - sub[i] * x[i - 1]) / m
        for i in range(n - 2, -1, -1):
            x[i] -= c[i] * x[i + 1]
        return x

    x = thomas(np.asarray(rhs, dtype=float))
    u = np.zeros(n)
    u[0], u[-1] = gamma, alpha
    z = thomas(u)
    factor = (x[0] + beta * x[-1] / gamma) / (1.0 + z[0] + beta * z[-1] / gamma)
    return x - factor * z


class TableProgram(ProgramBase):
    """Periodic cubic spline through (theta_i [rad], s_i [m]); the CamProgram interface.

    ``angles`` strictly increasing within one period (last - first < 2 pi),
    ``lifts`` >= 0, at least 3 points.  ``lift`` is the largest table lift [m].
    """

    def __init__(self, angles: Sequence[float], lifts: Sequence[float]) -> None:
        th = np.asarray(angles, dtype=float)
        y = np.asarray(lifts, dtype=float)
        if th.ndim != 1 or th.shape != y.shape:
            raise ValueError(f"angles and lifts must be two 1-D sequences of equal length, "
                             f"got shapes {th.shape} and {y.shape}")
        n = len(th)
        if n < 3:
            raise ValueError(f"a motion table needs at least 3 points, got {n}")
        if not (np.all(np.isfinite(th)) and np.all(np.isfinite(y))):
            raise ValueError("motion table angles and lifts must be finite numbers")
        steps = np.diff(th)
        if np.any(steps <= 0.0):
            k = int(np.argmax(steps <= 0.0))
            raise ValueError(f"motion table angles must increase strictly: point {k + 2} "
                             f"({math.degrees(th[k + 1]):.6g} deg) follows {math.degrees(th[k]):.6g} deg")
        if th[-1] - th[0] >= TWO_PI:
            raise ValueError(f"motion table angles must span less than 360 deg (one period), got "
                             f"{math.degrees(th[0]):.6g} .. {math.degrees(th[-1]):.6g} deg")
        if np.any(y < 0.0):
            k = int(np.argmax(y < 0.0))
            raise ValueError(f"motion table lift must be >= 0, got {y[k]!r} m at point {k + 1}")
        h = np.diff(np.append(th, th[0] + TWO_PI))            # h_i = x_{i+1} - x_i, periodic
        dy = (np.roll(y, -1) - y) / h                           # slope of chord i
        hp = np.roll(h, 1)                                      # h_{i-1}
        M = _solve_cyclic(hp, 2.0 * (hp + h), h, 6.0 * (dy - np.roll(dy, 1)))
        M1 = np.roll(M, -1)
        c1 = dy - h * (2.0 * M + M1) / 6.0
        c3 = (M1 - M) / (6.0 * h)
        self.angles = tuple(float(t) for t in th)               # knots [rad]
        self.lifts = tuple(float(v) for v in y)                 # table lifts [m]
        self.lift = float(y.max())
        # Piece i on [x_i, x_{i+1}], u = theta - x_i: s = c0 + c1 u + c2 u^2 + c3 u^3.
        self.coefficients = tuple((float(a), float(b), float(c), float(d))
                                  for a, b, c, d in zip(y, c1, 0.5 * M, c3))
        self.widths = tuple(float(v) for v in h)
        self._x0 = self.angles[0]
        self._coef = np.array(self.coefficients)
        self._knots = np.array(self.angles)

    def __repr__(self):
        return (f"TableProgram({len(self.angles)} knots, {math.degrees(self.angles[0]):.6g}.."
                f"{math.degrees(self.angles[-1]):.6g} deg, lift={self.lift!r})")

    def _reduce(self, theta: float) -> float:
        th = self._x0 + math.fmod(theta - self._x0, TWO_PI)
        if th < self._x0:
            th += TWO_PI
            if th >= self._x0 + TWO_PI:
                th = self._x0
        return th

    def derivatives(self, theta: float) -> tuple[float, float, float, float]:
        """(s [m], ds/dtheta [m/rad], d2s/dtheta2 [m/rad^2], d3s/dtheta3 [m/rad^3]), plain floats."""
        th = self._reduce(theta)
        i = bisect.bisect_left(self.angles, th) - 1
        if i < 0:                       # exactly the first knot: end of the last piece
            i = len(self.angles) - 1
            u = self.widths[i]
        else:
            u = th - self.angles[i]
        c0, c1, c2, c3 = self.coefficients[i]
        return (c0 + u * (c1 + u * (c2 + u * c3)), c1 + u * (2.0 * c2 + 3.0 * c3 * u),
                2.0 * c2 + 6.0 * c3 * u, 6.0 * c3)

    def evaluate(self, theta: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """The same four quantities over an array of theta [rad]."""
        theta = np.asarray(theta, dtype=float)
        th = self._x0 + np.mod(theta - self._x0, TWO_PI)
        th = np.where(th >= self._x0 + TWO_PI, self._x0, th)
        i = np.searchsorted(self._knots, th, side="left") - 1
        first = i < 0
        i = np.where(first, len(self.angles) - 1, i)
        u = np.where(first, np.asarray(self.widths)[-1], th - self._knots[np.maximum(i, 0)])
        c0, c1, c2, c3 = (self._coef[i, k] for k in range(4))
        s = c0 + u * (c1 + u * (c2 + u * c3))
        ds = c1 + u * (2.0 * c2 + 3.0 * c3 * u)
        d2s = 2.0 * c2 + 6.0 * c3 * u
        d3s = 6.0 * c3
        nan = np.isnan(theta)
        if nan.any():
            s, ds, d2s, d3s = (np.where(nan, np.nan, q) for q in (s, ds, d2s, d3s))
        return s, ds, d2s, d3s

    def feature_angle(self) -> float:
        """The shortest knot spacing [rad]: the profile's finest angular detail."""
        return min(self.widths)

    def breakpoints(self) -> tuple[float, ...]:
        """The knots reduced to [0, 2 pi), sorted: s''' jumps there."""
        return tuple(sorted(math.fmod(t, TWO_PI) for t in self.angles))


def parse_motion_table(text: str) -> tuple[list[float], list[float]]:
    """(angles [deg], lifts [mm]) from CSV text; see the module docstring for the format."""
    angles: list[float] = []
    lifts: list[float] = []
    header_seen = False
    for lineno, raw in enumerate(text.splitlines(), 1):
        line = raw.strip()
        if not line or line.startswith("#"):
            continue
        fields = [f for f in _SPLIT.split(line) if f]
        try:
            if len(fields) < 2:
                raise ValueError
            a, s = float(fields[0]), float(fields[1])
        except ValueError:
            if not header_seen and not angles:
                header_seen = True
                continue
            raise ValueError(f"motion table line {lineno}: expected two numbers 'angle_deg, lift_mm', "
                             f"got {raw.strip()!r}") from None
        if not (math.isfinite(a) and 0.0 <= a <= 360.0):
            raise ValueError(f"motion table line {lineno}: angle must lie in [0, 360] deg, got {a!r}")
        if not (math.isfinite(s) and s >= 0.0):
            raise ValueError(f"motion table line {lineno}: lift must be a finite number >= 0 mm, got {s!r}")
        angles.append(a)
        lifts.append(s)
    if len(angles) >= 2 and abs(angles[-1] - (angles[0] + 360.0)) <= 1e-9:
        if abs(lifts[-1] - lifts[0]) > 1e-9 * max(1.0, abs(lifts[0])):
            raise ValueError(f"motion table: the row at {angles[-1]:g} deg closes the period and must "
                             f"repeat the lift at {angles[0]:g} deg ({lifts[0]:g} mm), got {lifts[-1]:g} mm")
        angles.pop()
        lifts.pop()
    if len(angles) < 3:
        raise ValueError(f"motion table: need at least 3 rows 'angle_deg, lift_mm' in one period, "
                         f"got {len(angles)}")
    for k in range(1, len(angles)):
        if angles[k] <= angles[k - 1]:
            raise ValueError(f"motion table: angles must increase strictly, row {k + 1} "
                             f"({angles[k]:g} deg) follows {angles[k - 1]:g} deg")
    if angles[-1] - angles[0] >= 360.0:
        raise ValueError(f"motion table: angles span {angles[0]:g}..{angles[-1]:g} deg; one period "
                         f"(360 deg) at most, a closing row must repeat the first lift")
    return angles, lifts


def program_from_table_text(text: str) -> TableProgram:
    """A TableProgram from CSV text 'angle_deg, lift_mm' (the FMU's String parameter form)."""
    angles, lifts = parse_motion_table(text)
    return TableProgram([math.radians(a) for a in angles], [s * 1e-3 for s in lifts])


def read_motion_table(path: str | Path) -> TableProgram:
    """A TableProgram from a CSV file 'angle_deg, lift_mm' with a header line."""
    return program_from_table_text(Path(path).read_text())
