"""Geometry of a disc cam with a translating roller follower, in-line or offset.

Conventions (docs/cam_design.md draws them):

- Fixed frame: origin on the cam axis, the follower moves along +X (the rise
  direction), its axis is the line y = -e.  The cam turns counterclockwise
  (seen from +Z) by theta, the existing "forward" cam angle.
- r_b [m] is the prime-circle radius: from the cam axis to the roller centre
  at zero lift, so the roller centre is at (s0 + s, -e), s0 = sqrt(r_b^2 - e^2),
  and the base circle of the cam contour has radius r_b - r_r.  r_r = 0 is a knife edge (the contour is
  the pitch curve).
- e [m] is the offset (eccentricity).  e > 0 lowers the pressure angle on the
  rise and raises it on the return:  tan(alpha) = (s' - e) / (s0 + s).
- Cam frame: fixed to the cam, equal to the fixed frame at theta = 0.  The
  pitch curve (roller-centre path) there is
      c(theta) = Rot(-theta) (s0 + s, -e),
  traversed clockwise as theta grows.  All curves below are in the cam frame.
- Curvature kappa and radius of curvature rho = 1/kappa are signed: > 0 where
  the pitch curve is convex (bulges away from the cam axis side), < 0 where
  concave.  In closed form, with R = s0 + s and s' = ds/dtheta, s'' = d2s/dtheta2:
      rho_p = ((s' - e)^2 + R^2)^(3/2) / (R^2 + 2 s'^2 - 3 e s' + e^2 - R s'').
- Contours: the inner contour (the plate cam's working surface; the inner wall
  of a groove) is the pitch curve moved r_r along the inward normal,
  rho_inner = rho_p - r_r; the outer contour (the outer wall of a groove) is
  moved r_r outward, rho_outer = rho_p + r_r.  The inner contour reverses
  (undercut) where 0 < rho_p < r_r, the outer one where -r_r < rho_p < 0.

Units: m and rad.  numpy; scalar theta gives floats.
"""

from __future__ import annotations

import math
from typing import Protocol

import numpy as np

__all__ = ["DiscCam", "Program", "RollerCurves", "roller_radius_value"]


class Program(Protocol):
    """What the geometry needs of a cam program (CamProgram, TableProgram)."""

    def derivatives(self, theta: float) -> tuple[float, float, float, float]: ...
    def evaluate(self, theta: np.ndarray) -> tuple[np.ndarray, ...]: ...
    def breakpoints(self) -> tuple[float, ...]: ...


def _positive(name: str, value: float, unit: str = "m") -> float:
    value = float(value)
    if not (math.isfinite(value) and value > 0.0):
        raise ValueError(f"{name} must be a finite number > 0 [{unit}], got {value!r}")
    return value


def roller_radius_value(value: float) -> float:
    """The roller radius r_r [m] checked: finite and >= 0 (0: a knife edge)."""
    value = float(value)
    if not (math.isfinite(value) and value >= 0.0):
        raise ValueError(f"roller_radius r_r must be a finite number >= 0 [m] (0: a knife edge), got {value!r}")
    return value


class RollerCurves:
    """What every roller follower's cam derives from its pitch curve, its outward normal and the pitch
    curve's signed curvature (``pitch``, ``normal``, ``pitch_curvature`` of the class): the contours, their
    radii of curvature and the contour's base circle.  Needs ``base_radius`` and ``roller_radius`` [m]."""

    base_radius: float
    roller_radius: float

    @property
    def base_circle_radius(self) -> float:
        """Radius of the cam contour's base circle, r_b - r_r [m]."""
        return self.base_radius - self.roller_radius

    def contour(self, theta, side: str = "inner"):
        """Cam contour (x, y) [m]: 'inner' (plate cam surface, groove inner wall)
        or 'outer' (groove outer wall), the pitch curve moved r_r along the normal."""
        sign = _side_sign(side)
        x, y = self.pitch(theta)
        nx, ny = self.normal(theta)
        return x + sign * self.roller_radius * nx, y + sign * self.roller_radius * ny

    def pitch_radius_of_curvature(self, theta):
        """Signed radius of curvature of the pitch curve rho_p [m] (inf where straight)."""
        k = self.pitch_curvature(theta)
        with np.errstate(divide="ignore"):
            return np.divide(1.0, k) if np.ndim(k) else (math.inf if k == 0.0 else 1.0 / k)

    def contour_radius_of_curvature(self, theta, side: str = "inner"):
        """Signed radius of curvature of a contour [m]: rho_p - r_r (inner), rho_p + r_r (outer)."""
        return self.pitch_radius_of_curvature(theta) + _side_sign(side) * self.roller_radius


def _side_sign(side: str) -> float:
    sign = {"inner": -1.0, "outer": 1.0}.get(side)
    if sign is None:
        raise ValueError(f"side must be 'inner' or 'outer', got {side!r}")
    return sign


class DiscCam(RollerCurves):
    """A cam program on a disc: prime-circle radius r_b, roller radius r_r (0: a knife edge), offset e [m]."""

    def __init__(self, program: Program, base_radius: float, roller_radius: float,
                 offset: float = 0.0) -> None:
        r_b = _positive("base_radius (prime-circle radius r_b)", base_radius)
        r_r = roller_radius_value(roller_radius)
        e = float(offset)
        if not math.isfinite(e) or abs(e) >= r_b:
            raise ValueError(f"offset e must satisfy |e| < r_b = {r_b * 1e3:.6g} mm, "
                             f"got {e * 1e3!r} mm")
        if r_r >= r_b:
            raise ValueError(
                f"roller_radius r_r = {r_r * 1e3:.6g} mm must be < r_b = {r_b * 1e3:.6g} mm "
                f"(the prime-circle radius, to the roller centre): the cam's base circle "
                f"r_b - r_r would vanish")
        self.program = program
        self.base_radius = r_b
        self.roller_radius = r_r
        self.offset = e
        self.s0 = math.sqrt(r_b * r_b - e * e)

    def __repr__(self):
        return (f"DiscCam({self.program!r}, base_radius={self.base_radius!r}, "
                f"roller_radius={self.roller_radius!r}, offset={self.offset!r})")

    def _derivs(self, theta):
        if np.ndim(theta) == 0:
            return tuple(float(q) for q in self.program.derivatives(float(theta)))
        return self.program.evaluate(np.asarray(theta, dtype=float))

    # -- curves (cam frame) -----------------------------------------------------
    def pitch(self, theta):
        """Roller-centre path (x, y) [m] in the cam frame."""
        s = self._derivs(theta)[0]
        R = self.s0 + s
        c, sn = np.cos(theta), np.sin(theta)
        return R * c - self.offset * sn, -R * sn - self.offset * c

    def normal(self, theta):
        """Unit outward normal (nx, ny) of the pitch curve in the cam frame:
        from the cam towards the roller centre's side."""
        s, s1, _, _ = self._derivs(theta)
        R = self.s0 + s
        a = s1 - self.offset
        norm = np.hypot(R, a)
        nfx, nfy = R / norm, a / norm              # fixed frame: (R, s' - e) / |.|
        c, sn = np.cos(theta), np.sin(theta)
        return nfx * c + nfy * sn, -nfx * sn + nfy * c

    # -- curvature and pressure angle ------------------------------------------------
    def pitch_curvature(self, theta):
        """Signed curvature of the pitch curve [1/m]: > 0 convex, < 0 concave."""
        s, s1, s2, _ = self._derivs(theta)
        R = self.s0 + s
        e = self.offset
        num = R * R + 2.0 * s1 * s1 - 3.0 * e * s1 + e * e - R * s2
        return num / ((s1 - e) ** 2 + R * R) ** 1.5

    def pressure_angle(self, theta):
        """Signed pressure angle [rad]: between the contact normal and the follower
        axis, tan(alpha) = (s' - e) / (s0 + s); > 0 when the normal leans towards +Y."""
        s, s1, _, _ = self._derivs(theta)
        if np.ndim(theta) == 0:
            return math.atan2(s1 - self.offset, self.s0 + s)
        return np.arctan2(s1 - self.offset, self.s0 + s)
