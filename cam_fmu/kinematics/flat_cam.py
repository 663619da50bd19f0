"""Geometry of a disc cam with a flat-faced follower, translating or oscillating: the contour as the envelope
of the face's lines.

In the cam frame (disc_cam's frames: the cam turns counterclockwise by theta) the face at cam angle theta
is the line n(phi) . x = p, with n = (cos phi, sin phi) its unit normal pointing away from the cam and p
its distance from the cam axis.  The contour is the envelope of these lines: the contact point and the
contour's radius of curvature are

    x = p n + (dp/dphi) t,  t = (-sin phi, cos phi),       rho = p + d2p/dphi2,

with dp/dphi = p'/phi' and d2p/dphi2 = (p'' phi' - p' phi'') / phi'^3 (' = d/dtheta).  rho > 0 everywhere
is a contour without cusps; rho <= 0 somewhere cannot be made (the face would cut the cam's own contour).

- **translating_flat**: the face is perpendicular to the follower's axis +X at x = r_b + s (fixed frame):
  phi = -theta, p = r_b + s, so rho = r_b + s + s'' and the contact lies s' from the axis along the face,
  at (r_b + s, -s') in the fixed frame.  The face must reach from -max s' to -min s': its width
  max s' - min s'.  The contact normal is the axis: the pressure angle is 0.
- **oscillating_flat**: the face is a line through the pivot P, at d = ``pivot_distance`` from the cam
  axis; at zero lift it is the line x = r_b (touching the base circle on +X) with P = (r_b, sqrt(d^2 - r_b^2))
  on it.  The arm (and the face) turns counterclockwise by psi = lift_angle * S: the face's normal is
  (cos psi, sin psi) in the fixed frame, phi = psi - theta, p = r_b cos psi + sqrt(d^2 - r_b^2) sin psi
  = d sin(delta) with delta = delta0 + psi, sin(delta0) = r_b / d (the angle at P between PO and the face).
  The contact lies l = d cos(delta) / (1 - psi') from the pivot along the face: the face must reach from
  min l to max l, and 1 - psi' > 0, cos(delta) > 0 everywhere (else the contact runs off to infinity or
  behind the pivot).  The face passes through the pivot, so the contact's normal is the direction the
  face's point moves in: the pressure angle is 0.  The face's reference point, at ``arm_length`` from P
  along the face, traces the pitch curve.

Units: m and rad; numpy, scalar theta gives floats.
"""

from __future__ import annotations

import math

import numpy as np

from .arm_motion import ArmMotion
from .disc_cam import Program, _positive

__all__ = ["FlatFaceCam", "TranslatingFlatCam", "OscillatingFlatCam"]


class FlatFaceCam:
    """The envelope of a flat face's lines; subclasses give the line family (``_lines``) and the contact's
    position along the face (``face_position``)."""

    program: Program
    base_radius: float

    @property
    def base_circle_radius(self) -> float:
        """Radius of the cam contour's base circle, r_b [m] (the face touches it at zero lift)."""
        return self.base_radius

    def _lines(self, theta):
        """(p, p', p'', phi, phi', phi'') of the face's line in the cam frame at cam angle theta."""
        raise NotImplementedError

    def contour(self, theta, side: str = "inner"):
        """Cam contour (x, y) [m] in the cam frame: the contact point (a flat face has one side, 'inner')."""
        if side != "inner":
            raise ValueError(f"a flat face's cam has one contour, side 'inner', got {side!r}")
        p, p1, _, phi, f1, _ = self._lines(theta)
        c, s = np.cos(phi), np.sin(phi)
        q = p1 / f1
        return p * c - q * s, p * s + q * c

    def radius_of_curvature(self, theta):
        """The contour's signed radius of curvature rho = p + d2p/dphi2 [m]: > 0 convex (no cusp)."""
        p, p1, p2, _, f1, f2 = self._lines(theta)
        return p + (p2 * f1 - p1 * f2) / f1 ** 3

    def pressure_angle(self, theta):
        """Pressure angle [rad]: 0 (the contact normal is the direction the face's point moves in)."""
        return 0.0 if np.ndim(theta) == 0 else np.zeros(np.shape(theta))

    def face_position(self, theta):
        """The contact's position along the face [m] (see the subclass)."""
        raise NotImplementedError


class TranslatingFlatCam(FlatFaceCam):
    """A cam program on a disc under a flat face perpendicular to the follower's axis: base radius r_b [m]."""

    def __init__(self, program: Program, base_radius: float) -> None:
        self.program = program
        self.base_radius = _positive("base_radius r_b", base_radius)

    def __repr__(self):
        return f"TranslatingFlatCam({self.program!r}, base_radius={self.base_radius!r})"

    def _derivs(self, theta):
        if np.ndim(theta) == 0:
            return tuple(float(q) for q in self.program.derivatives(float(theta)))
        return self.program.evaluate(np.asarray(theta, dtype=float))

    def _lines(self, theta):
        s, s1, s2, _ = self._derivs(theta)
        th = np.asarray(theta, dtype=float) if np.ndim(theta) else float(theta)
        return self.base_radius + s, s1, s2, -th, -1.0, 0.0

    def face_position(self, theta):
        """The contact's offset along the face from the follower's axis [m], towards +Y of the fixed frame: -s'."""
        return -self._derivs(theta)[1]

    def pitch(self, theta):
        """The face's point on the axis, (r_b + s, 0) in the fixed frame, in the cam frame [m]."""
        R = self.base_radius + self._derivs(theta)[0]
        return R * np.cos(theta), -R * np.sin(theta)


class OscillatingFlatCam(FlatFaceCam):
    """A cam program on a disc under a flat face through the arm's pivot: base radius r_b, arm_length L (the
    face's reference point), pivot_distance d [m], lift_angle [rad]."""

    def __init__(self, program: Program, base_radius: float, arm_length: float, pivot_distance: float,
                 lift_angle: float) -> None:
        r_b = _positive("base_radius r_b", base_radius)
        L = _positive("arm_length L", arm_length)
        d = _positive("pivot_distance d", pivot_distance)
        if d <= r_b:
            raise ValueError(f"pivot_distance d = {d * 1e3:.6g} mm puts the pivot inside the base circle: "
                             f"a flat face through the pivot touching it needs d > r_b = {r_b * 1e3:.6g} mm")
        self.program = program
        self.arm = ArmMotion(program, lift_angle)
        self.base_radius, self.arm_length, self.pivot_distance = r_b, L, d
        self.lift_angle = self.arm.lift_angle
        self.delta0 = math.asin(r_b / d)
        self.pivot = (r_b, math.sqrt(d * d - r_b * r_b))

    def __repr__(self):
        return (f"OscillatingFlatCam({self.program!r}, base_radius={self.base_radius!r}, "
                f"arm_length={self.arm_length!r}, pivot_distance={self.pivot_distance!r}, "
                f"lift_angle={self.lift_angle!r})")

    def arm_angle(self, theta):
        """The arm's angle psi(theta) [rad] from its zero-lift position."""
        return self.arm.derivatives(theta)[0]

    def _lines(self, theta):
        psi, p1, p2, _ = self.arm.derivatives(theta)
        d, delta = self.pivot_distance, self.delta0 + psi
        sd, cd = np.sin(delta), np.cos(delta)
        return (d * sd, d * cd * p1, d * (cd * p2 - sd * p1 * p1), psi - theta, p1 - 1.0, p2)

    def face_position(self, theta):
        """The contact's distance from the pivot along the face, l = d cos(delta) / (1 - psi') [m]."""
        psi, p1, _, _ = self.arm.derivatives(theta)
        return self.pivot_distance * np.cos(self.delta0 + psi) / (1.0 - p1)

    def pitch(self, theta):
        """The face's reference point, arm_length from the pivot along the face, in the cam frame [m]."""
        psi = self.arm.derivatives(theta)[0]
        x = self.pivot[0] + self.arm_length * np.sin(psi)      # the face's direction from P: (sin psi, -cos psi)
        y = self.pivot[1] - self.arm_length * np.cos(psi)
        c, s = np.cos(theta), np.sin(theta)
        return x * c + y * s, -x * s + y * c
