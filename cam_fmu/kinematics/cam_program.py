"""A full cam cycle: rise, upper dwell, return, lower dwell over 2*pi.

theta is the cam angle [rad], s the follower lift [m] (docs/model.md section 1):

    rise   [0, b_r]:                    s = h S(phi/b_r),       phi = theta
    upper dwell (b_r, b_r + b_u]:       s = h
    return (.., b_r + b_u + b_d]:       s = h (1 - S(phi/b_d)), phi from return start
    lower dwell (.., 2 pi):             s = 0

ds/dtheta = h V / b, d2s/dtheta2 = h A / b^2, d3s/dtheta3 = h J / b^3 (with a
minus sign on the return).  Any real theta is reduced mod 2 pi first.

Convention at a breakpoint (only s'' and s''' can differ between the sides):
the piece *ending* there is used (left limit), except at theta = 0 (mod 2 pi),
which is the start of the rise (right limit, as MotionLaw does at T = 0).

This module imports math and numpy only (kinematics imports no other layer); the C engine's program
(``csrc/src/profile.c``) is held to it (tests/engine/test_engine_profile.py).
"""

from __future__ import annotations

import math
from typing import Sequence, Union

import numpy as np

from .motion_law import SHAPE_CONST, MotionLaw, golden_max
from .presets import law

__all__ = ["CamProgram", "ProgramBase", "paper_program"]

TWO_PI = 2.0 * math.pi

LawSpec = Union[str, Sequence[float], MotionLaw]


def _as_law(spec: LawSpec, what: str) -> MotionLaw:
    try:
        return law(spec)
    except ValueError as exc:
        raise ValueError(f"{what} law: {exc}") from None


class ProgramBase:
    """What every cam program offers on top of `derivatives`, `evaluate` and
    `breakpoints`: the in-line pressure angle and its maximum.  Subclasses:
    CamProgram (laws and dwells) and motion_table.TableProgram (a user table)."""

    def pressure_angle(self, theta, base_radius: float):
        """Pressure angle [rad] of the in-line roller follower,
        tan(alpha) = (ds/dtheta) / (r_b + s); signed (negative on the return).
        `base_radius` r_b [m] is the base-circle radius of the roller-centre
        (pitch) curve.  Scalar theta -> float, array -> array."""
        if not base_radius > 0.0:
            raise ValueError(f"base_radius must be > 0 [m], got {base_radius!r}")
        if np.ndim(theta) == 0:
            s, ds, _, _ = self.derivatives(float(theta))
            return math.atan(ds / (base_radius + s))
        s, ds, _, _ = self.evaluate(theta)
        return np.arctan(ds / (base_radius + s))

    def _points(self) -> tuple[float, ...]:
        points = self.__dict__.get("_breakpoints")
        if points is None:
            points = self._breakpoints = self.breakpoints()
        return points

    def breakpoints_passed(self, start: float, end: float) -> list[float]:
        """Breakpoint angles [rad] passed going from start to end, in the order passed.

        The list grows with the angle swept: for one step use ``first_breakpoint_passed``.
        """
        return crossed(self._points(), start, end)

    def first_breakpoint_passed(self, start: float, end: float) -> float | None:
        """The first breakpoint angle [rad] strictly between start and end, or None (O(1) in the angle swept)."""
        return first_crossed(self._points(), start, end)

    def max_pressure_angle(self, base_radius: float) -> tuple[float, float]:
        """(max |alpha| [rad], theta [rad] where it occurs) over one cycle."""
        n = 4096
        grid = np.unique(np.concatenate([np.linspace(0.0, TWO_PI, n, endpoint=False),
                                         np.array(self.breakpoints())]))
        alpha = np.abs(self.pressure_angle(grid, base_radius))
        k = int(np.argmax(alpha))
        best_t, best = float(grid[k]), float(alpha[k])
        a, b = float(grid[max(k - 1, 0)]), float(grid[min(k + 1, len(grid) - 1)])
        t, v = golden_max(lambda t: abs(self.pressure_angle(t, base_radius)), a, b, 1e-12)
        if v > best:
            best_t, best = t, v
        return best, best_t


# The shortest rise or return: 0.01 deg. The stroke's derivatives scale with 1/angle^3, which under- and
# overflows for angles near 0 (1e-300 deg divided by zero); no cam is cut with a shorter stroke.
MIN_STROKE_ANGLE = math.radians(0.01)


class CamProgram(ProgramBase):
    """Rise, upper dwell, return, lower dwell; angles in rad summing to 2 pi, lift in m."""

    def __init__(self, rise_law: LawSpec, return_law: LawSpec, lift: float,
                 rise_angle: float, upper_dwell: float, return_angle: float,
                 lower_dwell: float) -> None:
        self.rise_law = _as_law(rise_law, "rise")
        self.return_law = _as_law(return_law, "return")
        lift = float(lift)
        if not (math.isfinite(lift) and lift > 0.0):
            raise ValueError(f"lift must be a finite number > 0 [m], got {lift!r}")
        angles = {"rise_angle": rise_angle, "upper_dwell": upper_dwell,
                  "return_angle": return_angle, "lower_dwell": lower_dwell}
        angles = {k: float(v) for k, v in angles.items()}
        bad = [f"{k}={v!r}" for k, v in angles.items() if not (math.isfinite(v) and v >= 0.0)]
        if bad:
            raise ValueError(f"angles must be finite and >= 0 [rad]: {', '.join(bad)}")
        bad = [f"{k}={angles[k]!r}" for k in ("rise_angle", "return_angle") if angles[k] < MIN_STROKE_ANGLE]
        if bad:
            raise ValueError(f"rise and return angles must be >= {MIN_STROKE_ANGLE:.6g} rad (0.01 deg) [rad]: "
                             f"{', '.join(bad)}")
        total = sum(angles.values())
        if abs(total - TWO_PI) > 1e-9:
            detail = ", ".join(f"{k}={v:.6g}" for k, v in angles.items())
            raise ValueError(
                f"rise + upper dwell + return + lower dwell must be 2*pi = {TWO_PI:.9f} rad (360 deg); "
                f"got {total:.9f} rad ({math.degrees(total):.6g} deg) from {detail}")
        self.lift = lift
        self.rise_angle = angles["rise_angle"]
        self.upper_dwell = angles["upper_dwell"]
        self.return_angle = angles["return_angle"]
        self.lower_dwell = angles["lower_dwell"]
        # Phase ends, and precomputed scale factors for the hot path.
        self._b1 = self.rise_angle
        self._b2 = self._b1 + self.upper_dwell
        self._b3 = self._b2 + self.return_angle
        self._kr = (1.0 / self.rise_angle, lift / self.rise_angle,
                    lift / self.rise_angle ** 2, lift / self.rise_angle ** 3)
        self._kd = (1.0 / self.return_angle, lift / self.return_angle,
                    lift / self.return_angle ** 2, lift / self.return_angle ** 3)
        self._rise = self.rise_law.scalar
        self._ret = self.return_law.scalar
        self._breakpoints = self.breakpoints()

    def __repr__(self):
        return (f"CamProgram(rise_law={self.rise_law.T}, return_law={self.return_law.T}, "
                f"lift={self.lift!r}, rise_angle={self.rise_angle!r}, upper_dwell={self.upper_dwell!r}, "
                f"return_angle={self.return_angle!r}, lower_dwell={self.lower_dwell!r})")

    # -- evaluation ------------------------------------------------------------
    def derivatives(self, theta: float) -> tuple[float, float, float, float]:
        """(s [m], ds/dtheta [m/rad], d2s/dtheta2 [m/rad^2], d3s/dtheta3 [m/rad^3]), plain floats."""
        th = math.fmod(theta, TWO_PI)
        if th < 0.0:
            th += TWO_PI
            if th >= TWO_PI:      # -tiny + 2 pi rounds to 2 pi
                th = 0.0
        if th <= self._b1:
            k0, k1, k2, k3 = self._kr
            S, V, A, J = self._rise(th * k0)
            return self.lift * S, k1 * V, k2 * A, k3 * J
        if th <= self._b2:
            return self.lift, 0.0, 0.0, 0.0
        if th <= self._b3:
            k0, k1, k2, k3 = self._kd
            S, V, A, J = self._ret((th - self._b2) * k0)
            return self.lift * (1.0 - S), -k1 * V, -k2 * A, -k3 * J
        return 0.0, 0.0, 0.0, 0.0

    def evaluate(self, theta: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """The same four quantities over an array of theta [rad]."""
        theta = np.asarray(theta, dtype=float)
        th = np.mod(theta, TWO_PI)
        th = np.where(th >= TWO_PI, 0.0, th)
        h = self.lift
        rise = th <= self._b1
        upper = (th > self._b1) & (th <= self._b2)
        ret = (th > self._b2) & (th <= self._b3)
        k0, k1, k2, k3 = self._kr
        Sr, Vr, Ar, Jr = self.rise_law.evaluate(np.where(rise, th * k0, 0.0))
        d0, d1, d2, d3 = self._kd
        Sd, Vd, Ad, Jd = self.return_law.evaluate(np.where(ret, (th - self._b2) * d0, 0.0))
        s = np.where(rise, h * Sr, np.where(upper, h, np.where(ret, h * (1.0 - Sd), 0.0)))
        ds = np.where(rise, k1 * Vr, np.where(ret, -d1 * Vd, 0.0))
        d2s = np.where(rise, k2 * Ar, np.where(ret, -d2 * Ad, 0.0))
        d3s = np.where(rise, k3 * Jr, np.where(ret, -d3 * Jd, 0.0))
        nan = np.isnan(theta)
        if nan.any():
            s, ds, d2s, d3s = (np.where(nan, np.nan, q) for q in (s, ds, d2s, d3s))
        return s, ds, d2s, d3s

    def feature_angle(self) -> float:
        """The profile's finest angular detail [rad]: over both strokes, the angle over which
        a sine or cosine segment's phase advances by one radian, or a constant segment's length."""
        scales = []
        for beta, stroke_law in ((self.rise_angle, self.rise_law), (self.return_angle, self.return_law)):
            for seg in stroke_law.segments():
                scales.append(beta * (seg.F if seg.kind != SHAPE_CONST else seg.end - seg.start))
        return min(scales)

    def breakpoints(self) -> tuple[float, ...]:
        """Sorted angles in [0, 2 pi) where s'' or s''' may jump: every split
        point of both laws (zero-length segments included) and the dwell ends,
        duplicates (within 1e-12 rad) merged."""
        pts = [0.0]
        pts += [self.rise_angle * t for t in self.rise_law.T] + [self._b1, self._b2]
        pts += [self._b2 + self.return_angle * t for t in self.return_law.T] + [self._b3]
        out: list[float] = []
        for p in sorted(math.fmod(p, TWO_PI) for p in pts):
            if p >= TWO_PI - 1e-12:
                continue   # 2 pi is 0
            if not out or p - out[-1] > 1e-12:
                out.append(p)
        return tuple(out)


def crossed(points, start: float, end: float) -> list[float]:
    """Angles of the periodic points (in [0, 2 pi)) passed going from start to end [rad], in order."""
    lo, hi = min(start, end), max(start, end)
    out = []
    for p in points:
        k = math.ceil((lo - p) / TWO_PI)
        angle = p + k * TWO_PI
        while angle < hi:
            if angle > lo:
                out.append(angle)
            angle += TWO_PI
    out.sort(reverse=end < start)
    return out


def first_crossed(points, start: float, end: float) -> float | None:
    """The first of the periodic points (in [0, 2 pi)) passed going from start to end [rad], or None.

    Strictly between start and end, like ``crossed``; its cost does not grow with |end - start|
    (the integrators use it at every step).
    """
    found = first_angle_crossed(points, start, end)
    return None if math.isnan(found) else found


def first_angle_crossed(points: Sequence[float], start: float, end: float) -> float:
    """The first of the periodic angles ``points`` (each in [0, 2 pi)) strictly between start and end [rad],
    in the direction of travel, or NaN (none); its cost does not grow with |end - start|.

    Each point's nearest copy p + 2 pi k beyond start (k from one ceil or floor,
    not a loop over turns) is a candidate; the nearest candidate wins if it lies
    before end.
    """
    if end > start:
        best = math.inf
        for p in points:
            angle = p + math.ceil((start - p) / TWO_PI) * TWO_PI
            if angle <= start:
                angle += TWO_PI
            best = min(best, angle)
        return best if best < end else math.nan
    if end < start:
        best = -math.inf
        for p in points:
            angle = p + math.floor((start - p) / TWO_PI) * TWO_PI
            if angle >= start:
                angle -= TWO_PI
            best = max(best, angle)
        return best if best > end else math.nan
    return math.nan


def paper_program(A: float = 0.035) -> CamProgram:
    """The paper's profile (the paper's section 2.1; docs/model.md section 2): rise over
    [0, pi] and return over [pi, 2 pi] with the `paper` law, no dwells,
    lift h = 3 pi A / 2 (A = 35 mm -> h = 164.93 mm, peak ds/dtheta = 2 A)."""
    return CamProgram("paper", "paper", lift=1.5 * math.pi * A,
                      rise_angle=math.pi, upper_dwell=0.0, return_angle=math.pi, lower_dwell=0.0)
