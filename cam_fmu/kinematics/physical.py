"""Physical characteristic values of a cam program at a constant cam speed.

At n rpm the cam turns at omega = 2 pi n / 60 rad/s and the follower's
velocity, acceleration and jerk are v = s' omega, a = s'' omega^2,
j = s''' omega^3 (SI units: m/s, m/s^2, m/s^3), with s', s'', s''' the
derivatives of the lift over the cam angle.

Peaks are exact: for a CamProgram from the laws' characteristic values
(Vm, Am, Jm of each phase scaled by h / b^k, at the law's T times b); for a
TableProgram from its cubic pieces (s'' linear on each and jumping at the
knots, s''' constant on each).
Where s'' jumps (a law with unbounded jerk), the peak jerk is None and
``jerk_unbounded`` is True.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from .cam_program import CamProgram
from .characteristics import characteristics
from .motion_table import TableProgram

__all__ = ["FollowerPeaks", "follower_peaks", "omega_from_rpm"]


MAX_RPM = 1e6  # rpm; far above any cam, and low enough that v, a, j = s' w, s'' w^2, s''' w^3 stay finite


def omega_from_rpm(rpm: float) -> float:
    """Cam speed [rad/s] from rpm (> 0)."""
    rpm = float(rpm)
    if not (math.isfinite(rpm) and 0.0 < rpm <= MAX_RPM):
        raise ValueError(f"rpm = {rpm!r}: allowed (0, {MAX_RPM:g}] rpm")
    return 2.0 * math.pi * rpm / 60.0


@dataclass(frozen=True)
class FollowerPeaks:
    """Peak |v| [m/s], |a| [m/s^2], |j| [m/s^3] and the cam angles [rad] where they occur."""

    rpm: float
    omega: float
    velocity: float
    velocity_at: float
    acceleration: float
    acceleration_at: float
    jerk: float | None
    jerk_at: float | None
    jerk_unbounded: bool

    def to_json_dict(self) -> dict:
        deg = math.degrees
        return {"rpm": self.rpm, "omega_rad_s": self.omega,
                "peak_velocity_m_s": self.velocity, "peak_velocity_at_deg": deg(self.velocity_at),
                "peak_acceleration_m_s2": self.acceleration,
                "peak_acceleration_at_deg": deg(self.acceleration_at),
                "peak_jerk_m_s3": self.jerk,
                "peak_jerk_at_deg": None if self.jerk_at is None else deg(self.jerk_at),
                "jerk_unbounded": self.jerk_unbounded}

    def arm_json_dict(self, scale: float) -> dict:
        """The same peaks for an oscillating follower's arm, psi = scale * s (scale = lift_angle / lift
        [rad/m]): rate [rad/s], angular acceleration [rad/s^2] and jerk [rad/s^3]."""
        deg = math.degrees
        return {"rpm": self.rpm, "omega_rad_s": self.omega,
                "peak_arm_rate_rad_s": self.velocity * scale, "peak_arm_rate_at_deg": deg(self.velocity_at),
                "peak_arm_acceleration_rad_s2": self.acceleration * scale,
                "peak_arm_acceleration_at_deg": deg(self.acceleration_at),
                "peak_arm_jerk_rad_s3": None if self.jerk is None else self.jerk * scale,
                "peak_arm_jerk_at_deg": None if self.jerk_at is None else deg(self.jerk_at),
                "jerk_unbounded": self.jerk_unbounded}


def _best(cands):
    """(value, angle) of the largest value; ties -> the smallest angle."""
    top = max(v for v, _ in cands)
    return min(((v, t) for v, t in cands if v >= top * (1.0 - 1e-12)), key=lambda p: p[1])


def _cam_program_peaks(p: CamProgram):
    v, a, j = [], [], []
    unbounded = False
    for law_, start, b in ((p.rise_law, 0.0, p.rise_angle),
                           (p.return_law, p.rise_angle + p.upper_dwell, p.return_angle)):
        c = characteristics(law_)
        h = p.lift
        v.append((h * c.Vm / b, start + b * c.at["Vm"]))
        a.append((h * c.Am / b ** 2, start + b * c.at["Am"]))
        if c.jerk_unbounded:
            unbounded = True
        else:
            j.append((h * c.Jm / b ** 3, start + b * c.at["Jm"]))
    return _best(v), _best(a), (None if unbounded else _best(j))


def _table_peaks(p: TableProgram):
    v, a, j = [], [], []
    for x, w, (c0, c1, c2, c3), end in zip(p.angles, p.widths, p.coefficients, p.end_coefficients):
        v.append((abs(c1), x))                          # s' at the knot
        if c3 != 0.0:                                   # s'' = 0 inside: extreme of s'
            u = -c2 / (3.0 * c3)
            if 0.0 < u < w:
                v.append((abs(c1 + u * (2.0 * c2 + 3.0 * c3 * u)), x + u))
        # s'' is linear on the piece and jumps at the knots: its extremes are the two one-sided
        # limits at the piece's ends (right limit 2 c2 at x, left limit 2 e2 at x + w)
        a.append((abs(2.0 * c2), x))
        a.append((abs(2.0 * end[2]), x + w))
        j.append((abs(6.0 * c3), x))                    # s''' constant on the piece (from x on)
    return _best(v), _best(a), _best(j)


def follower_peaks(program, rpm: float) -> FollowerPeaks:
    """Peak follower velocity, acceleration and jerk at `rpm` (constant cam speed)."""
    omega = omega_from_rpm(rpm)
    if isinstance(program, CamProgram):
        (v, tv), (a, ta), jt = _cam_program_peaks(program)
    elif isinstance(program, TableProgram):
        (v, tv), (a, ta), jt = _table_peaks(program)
    else:
        raise TypeError(f"follower_peaks needs a CamProgram or a TableProgram, got {type(program).__name__}")
    two_pi = 2.0 * math.pi
    jerk, jerk_at = (None, None) if jt is None else (jt[0] * omega ** 3, jt[1] % two_pi)
    return FollowerPeaks(float(rpm), omega, v * omega, tv % two_pi, a * omega ** 2, ta % two_pi,
                         jerk, jerk_at, jt is None)
