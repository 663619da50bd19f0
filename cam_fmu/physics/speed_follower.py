"""The follower as a body of its own on a cam at imposed speed: the speed drive's hybrid system (docs/model.md 13).

The contact force, the flight and the impacts of ``follower``, put together for the reference
(reference/flight.py): which flank holds the follower, its acceleration in flight, the gaps, a touch-down
with the Zeno guard and the outputs. ``math`` only.
"""
from __future__ import annotations

import math

from .drive import sign, solve_guide_friction
from .follower import FlankFollower, Impact, contact_sign, impact, required_force
from .variables import output_record


class SpeedFollower(FlankFollower):
    """The follower as a body of its own on a cam at imposed speed (drive 'speed', closures 'form' and 'spring'),
    on the flank ``contact`` (+1, -1; FlankFollower) or off them (0). The cam's speed is imposed, so an impact leaves
    it unchanged (J_0 = inf in ``impact``)."""

    def held(self, theta: float, omega: float, omega_dot: float, contact: float) -> float:
        """N, > 0 while the flank ``contact`` holds the follower: contact times the force along X the flank must give
        (``contact_sign``, the friction at N = 0)."""
        s, s1, s2, _ = self.flank(theta, contact)
        return contact * contact_sign(self.m, s, s1, s2, omega, self.k, self.F0, self.F_gx, self.f0, omega_dot)

    def acceleration_scale(self, theta: float, omega: float, omega_dot: float) -> float:
        """m/s2, a bound of the follower's acceleration relative to the flank near theta (flight against cam), as the
        voltage drive's (voltage_follower.acceleration_scale) with the imposed omega_dot [rad/s2]: the closing force
        at the groove's middle over m, the guide's friction, s'' omega^2 and s' omega_dot."""
        s, s1, s2, _ = self.flank(theta, 0.0)
        return (abs(self.flank_closing(s, s1 * omega)) / self.m + self.f0 / self.m + abs(s2) * omega * omega
                + abs(s1 * omega_dot) + 1e-300)

    def land(self, theta: float, omega: float, omega_dot: float, v: float, contact: float) -> tuple[float, float, Impact]:
        """(contact after, v after [m/s], the impact) of a touch-down on the flank ``contact`` at theta.

        The relative velocity w = v - s' omega becomes -e w; a rebound that would rise less than ZENO_HEIGHT
        (w^2 < 2 A ZENO_HEIGHT, A = ``acceleration_scale``) ends in contact (plastic) where the flank holds the
        follower (a force of exactly 0 counts as held: the lift-off event, located from there, decides), else in
        flight at the flank's speed.
        """
        s1 = self.flank(theta, contact)[1]
        hit = impact(math.inf, self.m, s1, omega, v, self.e)
        w = hit.v - s1 * omega
        if self.rebounds(w, self.acceleration_scale(theta, omega, omega_dot)):
            return 0.0, hit.v, hit
        stay = contact if self.held(theta, omega, omega_dot, contact) >= 0.0 else 0.0  # a tie: the events decide
        return stay, s1 * omega, impact(math.inf, self.m, s1, omega, v, 0.0)

    def speed_step(self, theta: float, omega: float, omega_dot: float, v: float,
                   contact: float) -> tuple[float, float, Impact | None]:
        """(contact after, v after [m/s], the impact or None) where the imposed speed jumps to omega [rad/s] with the
        follower on the flank ``contact`` at speed v (a step of omega_ref, docs/model.md 13.2).

        The follower's speed is kept while the flank's jumps to s' omega, so the relative speed w = v - s' omega
        jumps too. A flank moving away from the follower (contact w > 0) stops pushing: it lifts off with v. A
        flank moving into it (contact w < 0) strikes it: ``land``, the impact law with restitution. Below the Zeno
        guard's speed (w^2 < 2 A ZENO_HEIGHT, the rebound ``land`` would call plastic) nothing happens: the
        follower stays on the flank at its speed.
        """
        s1 = self.flank(theta, contact)[1]
        w = v - s1 * omega
        if not self.rebounds(w, self.acceleration_scale(theta, omega, omega_dot)):
            return contact, s1 * omega, None
        if contact * w > 0.0:
            return 0.0, v, None
        return self.land(theta, omega, omega_dot, v, contact)

    def outputs(self, theta: float, omega: float, omega_dot: float, s: float, v: float, contact: float,
                direction: float | None = None) -> dict:
        """Every output of the speed drive with the follower's own s, v, a and the contact force N_contact [N];
        ``direction`` the way the cam moves, sgn(omega) unless given (at a stop, the way it moved into it)."""
        model = self.model
        s_cam, s1, s2, _ = self.program.derivatives(theta)
        tan_a = s1 / (model.r_b + s_cam)
        direction = sign(omega) if direction is None else direction
        shaft = model.M_f * direction

        def load(angle: float) -> tuple[float, float, float]:  # (M, J, force along X) with the follower on the flank
            sf, d1, d2, _ = self.flank(angle, contact)
            push = required_force(self.m, d2, omega, d1, omega_dot) + self.flank_closing(sf, d1 * omega)
            t_a = d1 / (model.r_b + self.program.derivatives(angle)[0])
            sigma = sign(d1 * direction)
            f = solve_guide_friction(push * t_a + model.G_y, t_a, sigma, model.mu, model.N_g, 0.0)
            force = push + sigma * f
            return shaft + force * d1, model.J_0 + self.m * d1 * d1, force

        if contact != 0.0:
            M, J, force = load(theta)
            s, v = s_cam - contact * self.c, s1 * omega
            a = s2 * omega * omega + s1 * omega_dot
            N = force * math.sqrt(1.0 + tan_a * tan_a)  # N, along the normal: force along X / cos(alpha), signed
        else:
            M, J, N = shaft, model.J_0, 0.0
            a = self.free_acceleration(s, sign(v)) if self.m > 0.0 else 0.0
        i = (model.J_0 * omega_dot + M) / model.c_m
        voltage = model.motor.voltage(i, omega)
        if model.L > 0.0 and omega != 0.0 and contact != 0.0:  # di/dt = omega dM/dtheta at constant speed
            d = 1e-6
            voltage += model.L * omega * (load(theta + d)[0] - load(theta - d)[0]) / (2 * d) / model.c_m
        record = output_record(omega=omega, theta=theta, s=s, i=i, M=M, J=J, v=v, a=a, alpha=math.atan(tan_a),
                               s_cam=s_cam, voltage=voltage, theta_m=theta, omega_m=omega, M_shaft=0.0, N_contact=N)
        record.update(contact=contact)   # variables.FOLLOWER_COLUMNS, with impacts (the reference's count)
        return record
