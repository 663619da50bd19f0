"""The follower as a body of its own on a voltage-driven cam (docs/model.md 13.6).

The consistent formulation (docs/model.md 5.1) with a rigid shaft and no guide friction, the follower held on
the cam's flank by a return spring (closure 'spring'), or in a groove with the clearance c (closure 'form': the
flanks at s_cam - c, pushing along +X, contact +1, and s_cam + c, contact -1). ``math`` only, written
independently of the C engine.

On a flank (s = s_cam - contact c, v = s' omega) the spring's force joins gravity's in the follower's load:

    J omega_dot = c_m i - M_f sgn(omega) - (m s'' omega^2 + F_close(s)) s',   J = J_0 + m s'^2
    P = m (s'' omega^2 + s' omega_dot) + F_close(s)        (the contact force along X, >= 0)

with F_close = F0 + k s - F_gx (follower.closing_force). Lift-off where contact P reaches 0. In flight the shaft
turns alone, J_0 omega_dot = c_m i - M_f sgn(omega), and m s_dd = -F_close(s). Touch-down where a gap closes: ``follower.impact`` with the shaft's inertia J_0 (momentum J_0 omega + m s' v kept, w+ = -e w-).
"""
from __future__ import annotations

import math

from .follower import Impact, closing_force, impact
from .speed_follower import ZENO_HEIGHT
from .variables import output_record


def sgn(x: float) -> float:
    """+1, -1 or 0."""
    return 1.0 if x > 0.0 else (-1.0 if x < 0.0 else 0.0)


class VoltageFollower:
    """The hybrid system of a follower of its own on a voltage-driven cam (``contact`` +1, -1 on a flank, 0 off)."""

    def __init__(self, model) -> None:
        self.model = model
        self.program = model.program
        self.motor = model.motor
        self.m, self.k, self.F0, self.F_gx = model.m, model.k_spring, model.F_spring0, model.F_gx
        self.J_0, self.M_f, self.e = model.J_0, model.M_f, model.restitution
        self.has_current = model.L > 0.0
        self.two_sided = model.closure == "form"
        self.c = model.c if self.two_sided else 0.0

    def torque(self, omega: float, i: float, u: float) -> float:
        """N m, the motor's c_m i (the state's i with L > 0, else quasi-static) less the shaft's friction."""
        drive = self.model.c_m * i if self.has_current else self.motor.quasi_static_torque(u, omega)
        return drive - self.M_f * sgn(omega)

    def current(self, omega: float, i: float, u: float) -> float:
        """A, the armature current: the state with L > 0, else quasi-static."""
        return i if self.has_current else self.motor.quasi_static_current(u, omega)

    def on_flank(self, theta: float, omega: float, drive: float, contact: float = 1.0) -> tuple[float, float]:
        """(omega_dot [rad/s2], P [N]) with the follower on the flank ``contact``: the module's coupled equations."""
        s, s1, s2, _ = self.program.derivatives(theta)
        s -= contact * self.c
        F = closing_force(s, self.k, self.F0, self.F_gx)
        omega_dot = (drive - (self.m * s2 * omega * omega + F) * s1) / (self.J_0 + self.m * s1 * s1)
        return omega_dot, self.m * (s2 * omega * omega + s1 * omega_dot) + F

    def free_acceleration(self, s: float) -> float:
        """m/s2, the flying follower's acceleration: -F_close(s) / m."""
        return -closing_force(s, self.k, self.F0, self.F_gx) / self.m

    def rates(self, y, u: float, contact: float) -> list[float]:
        """dy/dt of y = (theta, omega, i, s, v); on the flank s and v follow the cam (their rates are the cam's)."""
        theta, omega, i, s, v = y
        drive = self.torque(omega, i, u)
        di = self.motor.current_rate(u, i, omega) if self.has_current else 0.0
        if contact:
            omega_dot, _ = self.on_flank(theta, omega, drive, contact)
            _, s1, s2, _ = self.program.derivatives(theta)
            return [omega, omega_dot, di, s1 * omega, s2 * omega * omega + s1 * omega_dot]
        return [omega, drive / self.J_0, di, v, self.free_acceleration(s)]

    def contact_force(self, y, u: float, contact: float = 1.0) -> float:
        """N, contact P: the force the flank ``contact`` must give, along its normal (lift-off: contact while >= 0)."""
        return contact * self.on_flank(y[0], y[1], self.torque(y[1], y[2], u), contact)[1]

    def flank(self, theta: float, contact: float) -> tuple[float, float]:
        """(s [m], s' [m/rad]) of the follower on the flank ``contact`` at theta [rad]."""
        s, s1, _, _ = self.program.derivatives(theta)
        return s - contact * self.c, s1

    def gap(self, y, contact: float = 1.0) -> float:
        """m, the follower's distance from the flank ``contact`` (>= 0 in flight)."""
        return contact * (y[3] - self.flank(y[0], contact)[0])

    def acceleration_scale(self, y, u: float) -> float:
        """m/s2, a bound of the follower's acceleration relative to the flank near y."""
        theta, omega = y[0], y[1]
        s, s1, s2, _ = self.program.derivatives(theta)
        return (abs(self.free_acceleration(s)) + abs(s2) * omega * omega
                + abs(s1 * self.torque(omega, y[2], u) / self.J_0) + 1e-300)

    def land(self, y, u: float, contact: float = 1.0) -> tuple[float, list[float], Impact]:
        """(contact after, state after, the impact) at a touch-down: w = v - s' omega becomes -e w with the shaft's
        inertia J_0 taking -s' P; a rebound rising less than ZENO_HEIGHT (w^2 < 2 A ZENO_HEIGHT) is plastic, and the
        follower stays on the flank where it holds it (P >= 0)."""
        theta, omega, i, _, v = y
        s, s1 = self.flank(theta, contact)
        hit = impact(self.J_0, self.m, s1, omega, v, self.e)
        w = hit.v - s1 * hit.omega
        if w * w >= 2.0 * self.acceleration_scale(y, u) * ZENO_HEIGHT:
            return 0.0, [theta, hit.omega, i, s, hit.v], hit
        hit = impact(self.J_0, self.m, s1, omega, v, 0.0)
        after = [theta, hit.omega, i, s, s1 * hit.omega]
        return (contact if self.contact_force(after, u, contact) >= 0.0 else 0.0), after, hit

    def stored_energy(self, y) -> float:
        """J, the shaft's and follower's kinetic energy, the spring's F0 s + k s^2/2, gravity's -F_gx s, L i^2/2."""
        _, omega, i, s, v = y
        return (0.5 * self.J_0 * omega * omega + 0.5 * self.m * v * v + self.F0 * s + 0.5 * self.k * s * s
                - self.F_gx * s + 0.5 * self.model.L * i * i)

    def outputs(self, y, u: float, contact: float) -> dict[str, float]:
        """Every output of the drive, with the follower's own s, v, a and N_contact [N] (0 in flight)."""
        model = self.model
        theta, omega, i_state, s, v = y
        s_cam, s1, s2, _ = self.program.derivatives(theta)
        tan_a = s1 / (model.r_b + s_cam)
        drive = self.torque(omega, i_state, u)
        shaft = self.M_f * sgn(omega)
        if contact:
            omega_dot, P = self.on_flank(theta, omega, drive, contact)
            a, M, J = s2 * omega * omega + s1 * omega_dot, shaft + P * s1, self.J_0 + self.m * s1 * s1
            N = P * math.sqrt(1.0 + tan_a * tan_a)  # along the normal: P / cos(alpha), signed as contact
            s, v = s_cam - contact * self.c, s1 * omega
        else:
            a, M, J, N = self.free_acceleration(s), shaft, self.J_0, 0.0
        record = output_record(omega=omega, theta=theta, s=s, i=self.current(omega, i_state, u), M=M, J=J, v=v,
                               a=a, alpha=math.atan(tan_a), s_cam=s_cam, voltage=u, theta_m=theta, omega_m=omega,
                               M_shaft=0.0, N_contact=N)
        record.update(contact=contact)
        return record
