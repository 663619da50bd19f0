"""The follower as a body of its own on a voltage-driven cam (docs/model.md 13.6).

The consistent formulation (docs/model.md 5.1) with the follower held on the cam's flank by a return spring
(closure 'spring'), or in a groove with the clearance c (closure 'form': the flanks at s_cam - c, pushing along +X,
contact +1, and s_cam + c, contact -1), with guide friction and a rigid or compliant shaft. ``math`` only, written
independently of the C engine.

The cam side is driven by the torque T: the motor's c_m i on a rigid shaft, the shaft's k phi + d (omega_m - omega)
on a compliant one (docs/model.md 12.1), less the shaft's friction M_f sgn(omega). On a flank (s = s_cam - contact c,
v = s' omega) the contact's force along X, P = N_n cos(alpha) (N_n the normal force, signed as the flank pushes),
and the cam's acceleration solve two linear equations (the cam side's torque balance and the follower's force
balance along X), the guide's friction f = mu (|P tan(alpha) + G_y| + |N_g|) opposing v:

    J_0 omega_dot + s' P = T
    m (s'' omega^2 + s' omega_dot) = P - F_close(s) - sgn(v) f

with F_close = F0 + k s - F_gx (follower.closing_force); one branch per sign of the side force P tan(alpha) + G_y.
Lift-off where contact P reaches 0. In flight the cam side turns alone, J_0 omega_dot = T, and the follower obeys
m s_dd = -F_close(s) - sgn(v) f0 with the friction at no contact force f0 = mu (|G_y| + |N_g|); where v reaches 0
the friction turns, or holds the follower while |F_close| <= f0. Touch-down where a gap closes: ``follower.impact``
with the cam side's inertia J_0 (momentum J_0 omega + m s' v kept, w+ = -e w-; the guide's friction gives no
impulse).

At rest (omega = 0) the shaft is stuck (``heading`` 0: theta and omega held; on a flank s and v too, the flank's
force the static F_close(s); off it the follower flies alone and lands on the cam at rest, ``unstick``) until it would accelerate in one direction with M_f and the guide's friction against it (``start``, the
consistent formulation's break-away rule with the contact's load); moving, its direction ``heading`` is held until
a stop.
"""
from __future__ import annotations

import math

from .drive import sign as sgn
from .follower import FlankFollower, Impact, impact
from .modes import Mode, Shaft
from .variables import output_record


class VoltageFollower(FlankFollower):
    """The hybrid system of a follower of its own on a voltage-driven cam (``contact`` +1, -1 on a flank, 0 off).

    The state y is (theta, omega, i, s, v), with (phi, omega_m) after it on a compliant shaft (``size`` 7).
    """

    def __init__(self, model) -> None:
        super().__init__(model)
        self.motor, self.J_0, self.M_f = model.motor, model.J_0, model.M_f
        self.has_current = model.L > 0.0
        self.compliant = model.compliant
        self.size = 7 if self.compliant else 5
        self.mode = Mode()  # the run's mode: its shaft and direction are what ``heading`` reads

    @property
    def heading(self) -> float:
        """The shaft's direction, held over a piece (at omega = 0 where it starts: +1, -1), 0 while it is stuck."""
        return self.mode.heading

    @heading.setter
    def heading(self, value: float) -> None:
        if value == 0.0:
            self.mode.shaft = Shaft.STUCK
        else:
            self.mode.shaft, self.mode.direction = Shaft.TURNING, value

    def motor_speed(self, y) -> float:
        """rad/s, the rotor's speed: omega_m on a compliant shaft, else the cam's."""
        return y[6] if self.compliant else y[1]

    def current(self, y, u: float) -> float:
        """A, the armature current: the state with L > 0, else quasi-static at the rotor's speed."""
        return y[2] if self.has_current else self.motor.quasi_static_current(u, self.motor_speed(y))

    def shaft_torque(self, y) -> float:
        """N m, a compliant shaft's torque on the cam, k phi + d (omega_m - omega) (0 when rigid)."""
        if not self.compliant:
            return 0.0
        return self.model.k_shaft * y[5] + self.model.d_shaft * (y[6] - y[1])

    def torque(self, y, u: float, heading: float | None = None) -> float:
        """N m, what drives the cam side: the motor's c_m i (rigid) or the shaft's torque, less M_f sgn(omega)
        (``heading``: the direction the shaft moves in, at omega = 0 the one it starts in, 0 held)."""
        drive = self.shaft_torque(y) if self.compliant else self.model.c_m * self.current(y, u)
        return drive - self.M_f * (self.heading if heading is None else heading)

    def on_flank(self, theta: float, omega: float, drive: float, contact: float = 1.0,
                 heading: float | None = None) -> tuple[float, float, float]:
        """(omega_dot [rad/s2], P [N], f [N]) with the follower on the flank ``contact``: the module's equations
        (the guide's friction against s' times ``heading``, the shaft's direction, sgn(omega) unless given)."""
        s_cam, s1, s2, _ = self.program.derivatives(theta)
        F = self.flank_closing(s_cam - contact * self.c, s1 * omega)
        m, J_0 = self.m, self.J_0
        if self.mu == 0.0:
            omega_dot = (drive - (m * s2 * omega * omega + F) * s1) / (J_0 + m * s1 * s1)
            return omega_dot, m * (s2 * omega * omega + s1 * omega_dot) + F, 0.0
        sigma = sgn(s1 * (self.heading if heading is None else heading))
        tan_a = s1 / (self.model.r_b + s_cam)
        for side in (1.0, -1.0):  # the branch where the side force P tan(alpha) + G_y has the sign `side`
            slope = 1.0 - sigma * self.mu * side * tan_a  # dP/dP of P - sgn(v) f on this branch
            rest = m * s2 * omega * omega + F + sigma * self.mu * (side * self.G_y + self.N_g)
            # J_0 omega_dot + s' P = drive;  m s' omega_dot - slope P = -rest
            det = -J_0 * slope - m * s1 * s1
            omega_dot = (-drive * slope + s1 * rest) / det
            P = (-J_0 * rest - m * s1 * drive) / det
            if side * (P * tan_a + self.G_y) >= 0.0:
                break
        f = self.mu * (abs(P * tan_a + self.G_y) + self.N_g)
        return omega_dot, P, f

    def static_force(self, theta: float, contact: float) -> float:
        """N, the force P along X of the flank ``contact`` on the follower at rest on it, the cam held: it balances
        the spring and gravity, F_close(s) (the guide's friction carries nothing at rest)."""
        return self.flank_closing(self.flank(theta, contact)[0], 0.0)

    def start(self, y, u: float, contact: float) -> tuple[float, float]:
        """(margin [rad/s2], direction) of the shaft at rest: it starts toward ``direction`` where margin > 0 (the
        consistent formulation's break-away rule, DriveModel.breakaway_direction, with the follower's load on the
        flank ``contact``: the acceleration with the shaft's and the guide's friction against each direction;
        the cam side alone where contact is 0)."""
        at_rest = [y[0], 0.0, *y[2:]]
        if contact:
            forward = self.on_flank(y[0], 0.0, self.torque(at_rest, u, 1.0), contact, 1.0)[0]
            backward = -self.on_flank(y[0], 0.0, self.torque(at_rest, u, -1.0), contact, -1.0)[0]
        else:
            forward, backward = self.torque(at_rest, u, 1.0) / self.J_0, -self.torque(at_rest, u, -1.0) / self.J_0
        return (forward, 1.0) if forward >= backward else (backward, -1.0)

    def rates(self, y, u: float, contact: float, sigma: float = 0.0) -> list[float]:
        """dy/dt; on the flank s and v follow the cam (their rates are the cam's); in flight the friction's
        direction is -sigma (``direction``, held over a piece)."""
        theta, omega, i, s, v = y[:5]
        drive = self.torque(y, u)
        omega_m = self.motor_speed(y)
        di = self.motor.current_rate(u, i, omega_m) if self.has_current else 0.0
        if self.heading == 0.0:  # stuck: the cam held, the follower at rest on its flank or flying alone
            dy = [0.0, 0.0, di, 0.0, 0.0] if contact else [0.0, 0.0, di, v, self.free_acceleration(s, sigma)]
        elif contact:
            omega_dot, _, _ = self.on_flank(theta, omega, drive, contact)
            _, s1, s2, _ = self.flank(theta, contact)
            dy = [omega, omega_dot, di, s1 * omega, s2 * omega * omega + s1 * omega_dot]
        else:
            dy = [omega, drive / self.J_0, di, v, self.free_acceleration(s, sigma)]
        if self.compliant:  # the twist and the rotor: J_m omega_m_dot = c_m i - M_shaft
            dy += [omega_m - omega, (self.model.c_m * self.current(y, u) - self.shaft_torque(y)) / self.model.J_m]
        return dy

    def friction_power(self, y, u: float, contact: float, sigma: float) -> float:
        """W, the guide friction's dissipation f |v| (in flight f0 |v|)."""
        if contact:
            _, s1, _, _ = self.program.derivatives(y[0])
            return self.on_flank(y[0], y[1], self.torque(y, u), contact)[2] * abs(s1 * y[1])
        return self.f0 * abs(y[4]) if sigma else 0.0

    def side_force(self, y, u: float, contact: float) -> float:
        """N, the guide's side force N_r = P tan(alpha) + G_y on the flank ``contact`` (its sign is the friction's
        branch; |N_r| has a kink where it changes)."""
        s_cam, s1, _, _ = self.program.derivatives(y[0])
        P = self.on_flank(y[0], y[1], self.torque(y, u), contact)[1]
        return P * s1 / (self.model.r_b + s_cam) + self.G_y

    def contact_force(self, y, u: float, contact: float = 1.0) -> float:
        """N, contact P: the force the flank ``contact`` must give, along its normal (lift-off: contact while >= 0);
        the cam stuck, the static one."""
        if self.heading == 0.0:
            return contact * self.static_force(y[0], contact)
        return contact * self.on_flank(y[0], y[1], self.torque(y, u), contact)[1]

    def acceleration_scale(self, y, u: float) -> float:
        """m/s2, a bound of the follower's acceleration relative to the flank near y."""
        theta, omega = y[0], y[1]
        s, s1, s2, _ = self.flank(theta, 0.0)
        return (abs(self.flank_closing(s, s1 * omega)) / self.m + self.f0 / self.m
                + abs(s2) * omega * omega + abs(s1 * self.torque(y, u) / self.J_0) + 1e-300)

    def land(self, y, u: float, contact: float = 1.0) -> tuple[float, list[float], Impact]:
        """(contact after, state after, the impact) at a touch-down: w = v - s' omega becomes -e w with the cam side's
        inertia J_0 taking -s' P; a rebound rising less than ZENO_HEIGHT (w^2 < 2 A ZENO_HEIGHT) is plastic, and the
        follower stays on the flank where it holds it (P >= 0). A compliant shaft's rotor is not in the impact."""
        theta, omega, i, _, v = y[:5]
        s, s1, _, _ = self.flank(theta, contact)
        hit = impact(self.J_0, self.m, s1, omega, v, self.e)
        self.unstick(hit.omega)
        w = hit.v - s1 * hit.omega
        if self.rebounds(w, self.acceleration_scale(y, u)):
            return 0.0, [theta, hit.omega, i, s, hit.v, *y[5:]], hit
        hit = impact(self.J_0, self.m, s1, omega, v, 0.0)
        self.unstick(hit.omega)
        after = [theta, hit.omega, i, s, s1 * hit.omega, *y[5:]]
        return (contact if self.contact_force(after, u, contact) >= 0.0 else 0.0), after, hit

    def unstick(self, omega: float) -> None:
        """A stuck cam struck by the follower moves off where the impact turned it (the shaft's static friction, a
        finite force, gives no impulse); on a dwell (s' = 0) omega stays 0 and it stays stuck. A turning cam that the
        impact turns back (omega through 0 in the impulse) moves on the new way: the shaft's friction turns with it
        (a light cam struck by a heavy follower; held the old way, M_f sgn would feed the drive energy)."""
        if omega != 0.0 and self.heading != sgn(omega):
            self.heading = sgn(omega)

    def stored_energy(self, y) -> float:
        """J, the cam side's and follower's kinetic energy, the spring's F0 s + k s^2/2, gravity's -F_gx s, L i^2/2;
        on a compliant shaft the rotor's J_m omega_m^2/2 and the shaft's k phi^2/2 too."""
        _, omega, i, s, v = y[:5]
        energy = (0.5 * self.J_0 * omega * omega + 0.5 * self.m * v * v + self.F0 * s + 0.5 * self.k * s * s
                  - self.F_gx * s + 0.5 * self.model.L * i * i)
        if self.compliant:
            energy += 0.5 * self.model.J_m * y[6] ** 2 + 0.5 * self.model.k_shaft * y[5] ** 2
        return energy

    def outputs(self, y, u: float, contact: float) -> dict[str, float]:
        """Every output of the drive, with the follower's own s, v, a and N_contact [N] (0 in flight)."""
        model = self.model
        theta, omega, _, s, v = y[:5]
        s_cam, s1, s2, _ = self.program.derivatives(theta)
        tan_a = s1 / (model.r_b + s_cam)
        drive = self.torque(y, u)
        shaft = self.M_f * self.heading
        if contact and self.heading == 0.0:  # stuck: the shaft's static friction takes the drive's torque
            P, a, M, J = self.static_force(theta, contact), 0.0, drive, self.J_0 + self.m * s1 * s1
            N = P * math.sqrt(1.0 + tan_a * tan_a)  # signed as the flank: < 0 on the upper flank (contact -1)
            s, v = s_cam - contact * self.c, 0.0
        elif contact:
            omega_dot, P, _ = self.on_flank(theta, omega, drive, contact)
            a, M, J = s2 * omega * omega + s1 * omega_dot, shaft + P * s1, self.J_0 + self.m * s1 * s1
            N = P * math.sqrt(1.0 + tan_a * tan_a)  # along the normal: P / cos(alpha), signed as contact
            s, v = s_cam - contact * self.c, s1 * omega
        else:
            a, M, J, N = self.free_acceleration(s, self.direction(s, v)), shaft, self.J_0, 0.0
        theta_m, omega_m = (theta + y[5], y[6]) if self.compliant else (theta, omega)
        record = output_record(omega=omega, theta=theta, s=s, i=self.current(y, u), M=M,
                               J=J + (model.J_m if self.compliant else 0.0), v=v, a=a, alpha=math.atan(tan_a),
                               s_cam=s_cam, voltage=u, theta_m=theta_m, omega_m=omega_m, M_shaft=self.shaft_torque(y), N_contact=N)
        record.update(contact=contact)
        return record
