"""Geometry of a disc cam with an oscillating roller follower (a rocker arm with a roller, or a knife edge).

Conventions (docs/model.md section 15 draws them), in the fixed frame of disc_cam (origin on the cam axis,
the cam turning counterclockwise by theta; the cam frame is the fixed frame at theta = 0):

- The arm turns about the pivot P at the distance d = ``pivot_distance`` from the cam axis; the roller
  centre C sits at L = ``arm_length`` from P.  At zero lift C is on +X at the prime-circle radius r_b:
  C0 = (r_b, 0), and P lies on the +Y side, P = d (cos beta, sin beta) with, from the triangle
  (cam axis O, pivot P, roller centre C) and the law of cosines,
      cos beta   = (d^2 + r_b^2 - L^2) / (2 d r_b)       (the angle at O between OP and OC0),
      cos delta0 = (d^2 + L^2 - r_b^2) / (2 d L)         (the angle at P between PO and PC0).
- The arm's angle psi(theta) = lift_angle * S(theta) (arm_motion) turns it counterclockwise, away from the
  cam: the angle at P is delta = delta0 + psi, the arm's direction u = (cos phi, sin phi) with
  phi = beta + pi + delta, the roller centre C = P + L u, and |OC|^2 = d^2 + L^2 - 2 d L cos(delta).
- The roller centre's path is the circle about P; its direction w = (-sin phi, cos phi).  The pressure
  angle alpha is the angle between the contact normal (the pitch curve's normal) and w:
      tan(alpha) = (d cos(delta) - L (1 - psi')) / (d sin(delta)),
  > 0 when the normal leans from w towards the pivot.  It reaches 90 deg where delta reaches 0 or 180 deg.
- Pitch curve (cam frame) c(theta) = Rot(-theta) C(theta); its signed curvature (> 0 convex) follows from
  C, C' = L psi' w and C'' = L psi'' w - L psi'^2 u: c' = Rot(-theta)(C' - J C),
  c'' = Rot(-theta)(C'' - 2 J C' - C) (J the quarter turn), kappa = -(c' x c'') / |c'|^3.
- Contours, undercut and their radii of curvature as for the translating roller (disc_cam.RollerCurves).

Units: m and rad; numpy, scalar theta gives floats.
"""

from __future__ import annotations

import math

import numpy as np

from .arm_motion import ArmMotion
from .disc_cam import Program, RollerCurves, _positive, roller_radius_value

__all__ = ["OscillatingRollerCam", "rocker_angles"]


def rocker_angles(base_radius: float, arm_length: float, pivot_distance: float) -> tuple[float, float]:
    """(beta, delta0) [rad] of the triangle (cam axis, pivot, roller centre at zero lift) by the law of
    cosines; ValueError naming the limit when the arm cannot reach the prime circle."""
    r_b, L, d = base_radius, arm_length, pivot_distance
    if not (abs(d - L) < r_b < d + L):
        raise ValueError(
            f"the arm cannot reach the cam: arm_length L = {L * 1e3:.6g} mm and pivot_distance d = "
            f"{d * 1e3:.6g} mm need |d - L| < r_b < d + L, i.e. {abs(d - L) * 1e3:.6g} mm < r_b < "
            f"{(d + L) * 1e3:.6g} mm, with r_b = {r_b * 1e3:.6g} mm (the prime circle, to the roller centre)")
    beta = math.acos((d * d + r_b * r_b - L * L) / (2.0 * d * r_b))
    delta0 = math.acos((d * d + L * L - r_b * r_b) / (2.0 * d * L))
    return beta, delta0


class OscillatingRollerCam(RollerCurves):
    """A cam program on a disc driving a rocker: prime-circle radius r_b, roller radius r_r (0: knife
    edge), arm_length L, pivot_distance d [m], lift_angle [rad].  Parameter ranges are checked here; what
    needs the whole cycle (the pressure angle below 90 deg) is `follower_types.refuse_unbuildable`'s."""

    def __init__(self, program: Program, base_radius: float, roller_radius: float, arm_length: float,
                 pivot_distance: float, lift_angle: float) -> None:
        r_b = _positive("base_radius (prime-circle radius r_b)", base_radius)
        r_r = roller_radius_value(roller_radius)
        L = _positive("arm_length L", arm_length)
        d = _positive("pivot_distance d", pivot_distance)
        if r_r >= r_b:
            raise ValueError(f"roller_radius r_r = {r_r * 1e3:.6g} mm must be < r_b = {r_b * 1e3:.6g} mm "
                             f"(the prime circle): the cam's base circle r_b - r_r would vanish")
        if d <= r_b - r_r:
            raise ValueError(f"pivot_distance d = {d * 1e3:.6g} mm puts the pivot inside the cam's base circle: "
                             f"d must be > r_b - r_r = {(r_b - r_r) * 1e3:.6g} mm")
        self.beta, self.delta0 = rocker_angles(r_b, L, d)
        self.program = program
        self.arm = ArmMotion(program, lift_angle)
        self.base_radius, self.roller_radius = r_b, r_r
        self.arm_length, self.pivot_distance, self.lift_angle = L, d, self.arm.lift_angle
        self.pivot = (d * math.cos(self.beta), d * math.sin(self.beta))

    def __repr__(self):
        return (f"OscillatingRollerCam({self.program!r}, base_radius={self.base_radius!r}, "
                f"roller_radius={self.roller_radius!r}, arm_length={self.arm_length!r}, "
                f"pivot_distance={self.pivot_distance!r}, lift_angle={self.lift_angle!r})")

    # -- the arm in the fixed frame ------------------------------------------------------
    def _fixed(self, theta):
        """(C, C', C'' in the fixed frame as (x, y) pairs, delta, psi')."""
        psi, p1, p2, _ = self.arm.derivatives(theta)
        delta = self.delta0 + psi
        phi = self.beta + math.pi + delta
        ux, uy = np.cos(phi), np.sin(phi)
        L = self.arm_length
        C = (self.pivot[0] + L * ux, self.pivot[1] + L * uy)
        C1 = (-L * p1 * uy, L * p1 * ux)
        C2 = (-L * p2 * uy - L * p1 * p1 * ux, L * p2 * ux - L * p1 * p1 * uy)
        return C, C1, C2, delta, p1

    def arm_angle(self, theta):
        """The arm's angle psi(theta) [rad] from its zero-lift position."""
        return self.arm.derivatives(theta)[0]

    def roller_centre(self, theta):
        """The roller centre (x, y) [m] in the fixed frame."""
        return self._fixed(theta)[0]

    # -- curves (cam frame) -----------------------------------------------------------------
    def pitch(self, theta):
        """Roller-centre path (x, y) [m] in the cam frame."""
        (x, y), *_ = self._fixed(theta)
        c, s = np.cos(theta), np.sin(theta)
        return x * c + y * s, -x * s + y * c

    def _tangent(self, theta):
        """c' in the fixed frame's orientation: C' - J C (the cam frame's is Rot(-theta) of it)."""
        (x, y), (x1, y1), *_ = self._fixed(theta)
        return x1 + y, y1 - x

    def normal(self, theta):
        """Unit outward normal (nx, ny) of the pitch curve in the cam frame: the tangent turned +90 deg
        (the pitch curve runs clockwise)."""
        tx, ty = self._tangent(theta)
        norm = np.hypot(tx, ty)
        nfx, nfy = -ty / norm, tx / norm
        c, s = np.cos(theta), np.sin(theta)
        return nfx * c + nfy * s, -nfx * s + nfy * c

    def pitch_curvature(self, theta):
        """Signed curvature of the pitch curve [1/m]: > 0 convex, < 0 concave."""
        (x, y), (x1, y1), (x2, y2), _, _ = self._fixed(theta)
        ax, ay = x1 + y, y1 - x                        # C' - J C
        bx, by = x2 + 2.0 * y1 - x, y2 - 2.0 * x1 - y  # C'' - 2 J C' - C
        return -(ax * by - ay * bx) / (ax * ax + ay * ay) ** 1.5

    def pressure_angle(self, theta):
        """Signed pressure angle [rad] between the contact normal and the roller centre's path:
        tan(alpha) = (d cos(delta) - L (1 - psi')) / (d sin(delta)); |alpha| >= 90 deg where sin(delta) <= 0."""
        _, _, _, delta, p1 = self._fixed(theta)
        d, L = self.pivot_distance, self.arm_length
        if np.ndim(theta) == 0:
            return math.atan2(d * math.cos(delta) - L * (1.0 - p1), d * math.sin(delta))
        return np.arctan2(d * np.cos(delta) - L * (1.0 - p1), d * np.sin(delta))
