"""A follower of its own for every kind: lift-off, flight and impacts in the kind's coordinate (docs/model.md 16.3).

The translating roller's follower of its own (follower.FlankFollower, voltage_follower.VoltageFollower,
speed_follower.SpeedFollower) written in the kind's coordinate q (physics.kind_drive.KindDriveModel): s -> q (a
translating face's s [m], an arm's psi [rad]), m -> I_f (m, or J_arm + m L^2), F_close -> Q_close, c -> c_q = c / l
with l = 1 (translating) or the arm's length L. The state's (s, v) slots hold (q_f, q_f_dot); the hybrid runs of
reference/flight.py and reference/voltage_flight.py run these classes unchanged.

    Q_close(q) = l (F_spring0 + k_spring l q) + dV/dq      (the spring along the roller's path at l, gravity's V)
    V_close(q) = l F_spring0 q + k_spring l^2 q^2 / 2 + V(q)

On a flank the drive equation is 16's with Q_close(q_f) for dV/dq, the friction's branch b = contact (no side event:
its kink is the lift-off); in flight I_f q_f'' = -Q_close(q_f) with no friction (a face's sliding and an arm's pivot
friction act with the contact's force); an impact is follower.impact with I_f on the lever q'. The Zeno guard's height
is ZENO_HEIGHT / l. ``math`` only, written from docs/model.md 16.3 (not from the C engine).
"""
from __future__ import annotations

import math

from .drive import sign
from .follower import ZENO_HEIGHT
from .speed_follower import SpeedFollower
from .variables import output_record
from .voltage_follower import VoltageFollower

__all__ = ["KindFlank", "KindSpeedFollower", "KindVoltageFollower"]


class KindFlank:
    """The kind's terms of a follower of its own (a mixin before FlankFollower's subclasses): the flank, the closing
    force, the gaps, the stored energy and the outputs' contact force, all in the kind's coordinate q."""

    def _kind(self, model) -> None:
        kind = model.kind
        self.l = kind.arm_length if kind.oscillating else 1.0  # m, the path's length per unit of q
        self.c = self.c / self.l  # c_q [m or rad]
        self.m = model.I_f  # kg, or kg m2: the follower's inertia in q
        self.f0 = 0.0  # no friction in flight (it acts with the contact's force only)
        self.mu = model.mu
        self.zeno = ZENO_HEIGHT / self.l
        self.scale = model._scale  # q per m of the law's lift

    def flank(self, theta: float, contact: float) -> tuple[float, float, float, float]:
        """(q_f, q', q'', q_cam) of the follower on the flank ``contact`` at theta [rad] (q' per rad of theta)."""
        q, q1, q2, _ = self.model.coordinate(theta)
        return q - contact * self.c, q1, q2, q

    def closing(self, q: float) -> float:
        """Q_close(q) [N, or N m about an arm's pivot]: the spring along the path at l and gravity's dV/dq."""
        return self.l * (self.F0 + self.k * self.l * q) + self.model.potential_slope(q)

    def closing_potential(self, q: float) -> float:
        """V_close(q) [J]: the spring's l F0 q + k l^2 q^2 / 2 and gravity's V (16.3)."""
        model = self.model
        if model.kind.oscillating:
            V = model.W * math.sin(q + model.kind.psi_0) if model.W else 0.0
        else:
            V = -model.F_gx * q
        return self.l * self.F0 * q + 0.5 * self.k * self.l * self.l * q * q + V

    def gaps(self, theta: float, q: float) -> tuple[float, float]:
        """(gap to the +1 flank, gap to the -1 flank) [m along the follower's path: l times the gap in q]."""
        q_cam = self.model.coordinate(theta)[0]
        upper = ((q_cam + self.c) - q) * self.l if self.two_sided else math.inf
        return (q - (q_cam - self.c)) * self.l, upper

    def lever_at(self, theta: float) -> float:
        """lambda at the cam's q(theta) (16's lever; 0 without friction)."""
        if not self.mu:
            return 0.0
        q, q1, _, s = self.model.coordinate(theta)
        return self.model.lever(q, q1, s)

    def normal_force(self, theta: float, P: float, direction: float) -> tuple[float, float]:
        """(N_contact [N], alpha [rad]) from P as 16 gives them (the cam's geometry at theta)."""
        model, kind = self.model, self.model.kind
        q, q1, _, _ = model.coordinate(theta)
        if kind.follower_type == "oscillating_roller":
            alpha = float(model.cam.pressure_angle(theta))
            return (P + self.mu * abs(P) * sign(q1 * direction)) / (kind.arm_length * math.cos(alpha)), alpha
        if kind.follower_type == "oscillating_flat":
            return P * (1.0 - q1) / (kind.pivot_distance * math.cos(model._delta0 + q)), 0.0
        return P, 0.0

    def record(self, **values) -> dict[str, float]:
        """The output row from the follower's own q_f, q_f_dot, q_f_dd (keys q, qd, qa) and the drive's values."""
        q, qd, qa = values.pop("q"), values.pop("qd"), values.pop("qa")
        arm = self.model.kind.oscillating
        row = output_record(s=q / self.scale, v=qd / self.scale, a=qa / self.scale, psi=q if arm else 0.0,
                            psi_dot=qd if arm else 0.0, **values)
        return row


class KindVoltageFollower(KindFlank, VoltageFollower):
    """The voltage drive's follower of its own for another kind (docs/model.md 16.3); a rigid shaft only."""

    def __init__(self, model) -> None:
        super().__init__(model)
        self._kind(model)

    def on_flank(self, theta: float, omega: float, drive: float, contact: float = 1.0,
                 heading: float | None = None) -> tuple[float, float, float]:
        """(omega_dot [rad/s2], P [N or N m], lambda) on the flank ``contact``: (J_0 + I_f q' k) omega_dot = drive -
        (I_f q'' omega^2 + Q_close(q_f)) k, k = q' + mu lambda d contact, P = I_f (q'' omega^2 + q' omega_dot) +
        Q_close(q_f) (``drive`` the cam side's torque less M_f d, d the shaft's direction ``heading``)."""
        q, q1, q2, _ = self.flank(theta, contact)
        d = self.heading if heading is None else heading
        A = self.m * q2 * omega * omega + self.flank_closing(q, q1 * omega)
        lam = self.lever_at(theta)
        k = q1 + self.mu * lam * d * contact
        omega_dot = (drive - A * k) / (self.J_0 + self.m * q1 * k)
        return omega_dot, A + self.m * q1 * omega_dot, lam

    def side_force(self, y, u: float, contact: float) -> float:
        """0: on a flank the friction's branch is the contact's (no side event)."""
        return 0.0

    def friction_power(self, y, u: float, contact: float, sigma: float) -> float:
        """W, mu contact P lambda |omega| on a flank (the branch's power, mu |P| lambda |omega| while it holds); 0
        in flight and stuck."""
        if not contact or y[1] == 0.0 or not self.mu:
            return 0.0
        _, P, lam = self.on_flank(y[0], y[1], self.torque(y, u), contact)
        return self.mu * contact * P * lam * abs(y[1])

    def stored_energy(self, y) -> float:
        """J: (1/2) J_0 omega^2 + (1/2) I_f q_f_dot^2 + V_close(q_f) + (1/2) L i^2 (16.3)."""
        _, omega, i, q, qd = y[:5]
        return (0.5 * self.J_0 * omega * omega + 0.5 * self.m * qd * qd + self.closing_potential(q)
                + 0.5 * self.model.L * i * i)

    def outputs(self, y, u: float, contact: float) -> dict[str, float]:
        """Every output, the follower's own s, v, a (law's lift units), psi, psi_dot and N_contact (16.3)."""
        theta, omega, _, q, qd = y[:5]
        q_cam, q1, q2, s_cam = self.model.coordinate(theta)
        drive = self.torque(y, u)
        heading = self.heading
        P = 0.0
        if contact and heading == 0.0:  # stuck: the shaft's static friction takes the drive's torque
            P, qa, M, J = self.static_force(theta, contact), 0.0, drive, self.J_0 + self.m * q1 * q1
            q, qd = q_cam - contact * self.c, 0.0
        elif contact:
            omega_dot, P, lam = self.on_flank(theta, omega, drive, contact)
            qa = q2 * omega * omega + q1 * omega_dot
            M = self.M_f * heading + P * q1 + self.mu * abs(P) * lam * heading
            J = self.J_0 + self.m * q1 * q1
            q, qd = q_cam - contact * self.c, q1 * omega
        else:
            qa, M, J = self.free_acceleration(q, 0.0), self.M_f * heading, self.J_0
        N, alpha = self.normal_force(theta, P, heading) if contact else (0.0, 0.0)
        row = self.record(q=q, qd=qd, qa=qa, omega=omega, theta=theta, i=self.current(y, u), M=M, J=J,
                          alpha=alpha if contact else self.normal_force(theta, 0.0, 1.0)[1], s_cam=s_cam,
                          voltage=u, theta_m=theta, omega_m=omega, M_shaft=0.0, N_contact=N)
        row.update(contact=contact)
        return row


class KindSpeedFollower(KindFlank, SpeedFollower):
    """The speed drive's follower of its own for another kind (docs/model.md 16.3): the cam's J_0 infinite."""

    def __init__(self, model) -> None:
        super().__init__(model)
        self._kind(model)

    def held(self, theta: float, omega: float, omega_dot: float, contact: float) -> float:
        """N or N m, > 0 while the flank ``contact`` holds the follower: contact P, P = I_f (q'' omega^2 + q'
        omega_dot) + Q_close(q_f)."""
        q, q1, q2, _ = self.flank(theta, contact)
        return contact * (self.m * (q2 * omega * omega + q1 * omega_dot) + self.flank_closing(q, q1 * omega))

    def outputs(self, theta: float, omega: float, omega_dot: float, s: float, v: float, contact: float,
                direction: float | None = None) -> dict:
        """Every output of the speed drive with the follower's own q_f (``s``), q_f_dot (``v``) (16.3)."""
        model = self.model
        direction = sign(omega) if direction is None else direction
        q_cam, q1, q2, s_cam = model.coordinate(theta)

        def load(angle: float) -> tuple[float, float]:  # (M [N m], P) with the follower on the flank
            qf, d1, d2, _ = self.flank(angle, contact)
            P = self.m * (d2 * omega * omega + d1 * omega_dot) + self.flank_closing(qf, d1 * omega)
            return model.M_f * direction + P * d1 + self.mu * abs(P) * self.lever_at(angle) * direction, P

        if contact != 0.0:
            M, P = load(theta)
            J = model.J_0 + self.m * q1 * q1
            q, qd, qa = q_cam - contact * self.c, q1 * omega, q2 * omega * omega + q1 * omega_dot
            N, alpha = self.normal_force(theta, P, direction)
        else:
            M, J, N, q, qd = model.M_f * direction, model.J_0, 0.0, s, v
            qa = self.free_acceleration(q, 0.0) if self.m > 0.0 else 0.0
            alpha = self.normal_force(theta, 0.0, 1.0)[1]
        i = (model.J_0 * omega_dot + M) / model.c_m
        voltage = model.motor.voltage(i, omega)
        if model.L > 0.0 and omega != 0.0 and contact != 0.0:  # di/dt = omega dM/dtheta at constant speed
            h = 1e-6
            voltage += model.L * omega * (load(theta + h)[0] - load(theta - h)[0]) / (2 * h) / model.c_m
        row = self.record(q=q, qd=qd, qa=qa, omega=omega, theta=theta, i=i, M=M, J=J, alpha=alpha, s_cam=s_cam,
                          voltage=voltage, theta_m=theta, omega_m=omega, M_shaft=0.0, N_contact=N)
        row.update(contact=contact)
        return row
