"""The consistent cam drive as a hybrid system: continuous states, modes, events.

Continuous state y = (theta [rad], omega [rad/s]) and, when L > 0, i [A]
(slots THETA, OMEGA, CURRENT); a compliant shaft (k_shaft > 0, docs/model.md section 12)
adds its twist theta_m - theta [rad] and the rotor's speed omega_m [rad/s] (slots TWIST,
OMEGA_M; the CURRENT slot is then always there, constant with L = 0).
Discrete mode: stuck (shaft held by static friction), direction of motion,
backlash contact (+1: the cam drives the follower up, -1: down, 0: free in the
gap) and the follower's position while free. The scipy reference integrates
``derivative`` and stops at the zeros of ``event_values`` (docs/model.md sections
5-6). This is the readable model, written independently of the run-time engine in
C (cam_fmu/engine/csrc: cam_rhs, cam_event_value, cam_apply_event), which it checks:
FMU against reference compares the two.

Events are functions that are > 0 while nothing happens; a crossing to <= 0
triggers ``apply_event`` with the index of the function.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

from ..drive import DriveModel
from ..modes import Event, Follower, Shaft
from ..variables import output_record

THETA, OMEGA, CURRENT, TWIST, OMEGA_M = 0, 1, 2, 3, 4  # slots of the continuous state y
# The events of the hybrid system (docs/model.md section 10); an engine's event codes index this tuple.
EVENT_NAMES = ("stop", "contact", "engage_up", "engage_down", "break_away", "side_force", "halt")
STOP, CONTACT, ENGAGE_UP, ENGAGE_DOWN, BREAK_AWAY, SIDE, HALT = EVENT_NAMES
# Each of them in the one enumeration of the reference's events (physics/modes.py): the contact loss is the groove's
# lift-off, an engagement a touch-down (plastic here).
EVENTS = dict(zip(EVENT_NAMES, (Event.STOP, Event.LIFT_OFF, Event.TOUCH_LOWER, Event.TOUCH_UPPER, Event.BREAK_AWAY,
                                Event.SIDE, Event.HALT)))
EVENT_NAME = {kind: name for name, kind in EVENTS.items()}
# N [N]: the side-force event fires at N_r = -side * SIDE_HYSTERESIS, so a side force that stays
# exactly 0 (tan(alpha) = 0 and no sideways gravity, e.g. at theta = 0) cannot flip the branch
# back and forth at one instant (it did: the reference looped at a break-away from theta = 0).
SIDE_HYSTERESIS = 1e-9


@dataclass
class Mode:
    """Discrete state. ``contact`` is +1 with no backlash (always engaged)."""

    stuck: bool = False
    direction: float = 1.0  # sgn(omega) while moving
    contact: int = 1
    s_free: float = 0.0  # m, follower position while contact == 0
    side: float = 1.0  # sign of the guide's side force N_r (the friction branch) while engaged and moving

    @property
    def follower(self) -> Follower:
        """The named mode of the follower: on a flank (contact +1, -1; always without backlash), else in flight."""
        return Follower.flank(self.contact)

    @property
    def shaft(self) -> Shaft:
        """The named mode of the shaft: stuck or turning (``direction``)."""
        return Shaft.STUCK if self.stuck else Shaft.TURNING

    def copy(self) -> "Mode":
        return Mode(self.stuck, self.direction, self.contact, self.s_free, self.side)


class HybridDrive:
    """Consistent formulation of the drive under a voltage input u [V]."""

    def __init__(self, model: DriveModel) -> None:
        self.model = model
        self.motor = model.motor
        self.has_current = model.L > 0.0
        self.backlash = model.c > 0.0
        self.compliant = model.compliant
        self.size = 5 if self.compliant else (3 if self.has_current else 2)
        self.guide_side = model.mu > 0.0 and model.follower  # the side force's sign is an event
        self.feature_angle = model.program.feature_angle()  # rad

    # ------------------------------------------------------------ set-up
    def initial(self, theta0: float, omega0: float, i0: float) -> tuple[list[float], Mode]:
        """Initial state and mode (from rest: stuck until ``settle`` lets it go)."""
        y = [theta0, omega0, i0 if self.has_current else 0.0, 0.0, omega0][: self.size]
        mode = Mode(stuck=omega0 == 0.0, direction=1.0 if omega0 >= 0.0 else -1.0)
        if self.backlash:
            # The paper's step 1: the follower starts where the cam is, centred in the gap.
            mode.contact = 0
            mode.s_free = self.model.program.derivatives(theta0)[0]
        return y, mode

    def motor_speed(self, y) -> float:
        """The rotor's speed [rad/s]: the cam's, or omega_m beyond a compliant shaft."""
        return y[OMEGA_M] if self.compliant else y[OMEGA]

    def torque(self, y, u: float) -> float:
        """Motor torque c_m i [N m]."""
        if self.has_current:
            return self.motor.c_m * y[CURRENT]
        return self.motor.quasi_static_torque(u, self.motor_speed(y))

    def drive_torque(self, y, u: float, omega: float) -> float:
        """The torque that drives the cam [N m]: the motor's, or the compliant shaft's
        k twist + d (omega_m - omega) with omega the cam's speed (0 while it is held)."""
        if self.compliant:
            model = self.model
            return model.k_shaft * y[TWIST] + model.d_shaft * (y[OMEGA_M] - omega)
        return self.torque(y, u)

    def current(self, y, u: float) -> float:
        """Armature current [A]: the state, or quasi-static with L = 0."""
        return y[CURRENT] if self.has_current else self.motor.quasi_static_current(u, self.motor_speed(y))

    # -------------------------------------------------------- continuous
    def derivative(self, y, u: float, mode: Mode) -> tuple[float, ...]:
        """dy/dt. While moving, friction opposes mode.direction (fixed over a step)."""
        return self.rhs(u, mode)(y)

    def rhs(self, u: float, mode: Mode):
        """dy/dt as a function of y alone, for the input u and the mode as they are now.

        The integrators' hot path: the mode's values are bound once, so a
        right-hand-side evaluation is one call into DriveModel.omega_dot. Build
        it again after the mode changes (an event).
        """
        if self.compliant:
            return self._compliant_rhs(u, mode)
        model, motor = self.model, self.motor
        c_m = motor.c_m
        current_rate, quasi_static_torque = motor.current_rate, motor.quasi_static_torque
        omega_dot = model.omega_dot
        direction, engaged = mode.direction, mode.contact != 0
        side = mode.side if self.guide_side else 0.0
        if self.has_current:
            if mode.stuck:
                return lambda y: (0.0, 0.0, current_rate(u, y[CURRENT], y[OMEGA]))

            def with_current(y):
                omega, i = y[OMEGA], y[CURRENT]
                return (omega, omega_dot(y[THETA], omega, c_m * i, direction, engaged, side),
                        current_rate(u, i, omega))
            return with_current
        if mode.stuck:
            return lambda y: (0.0, 0.0)

        def quasi_static_current(y):
            omega = y[OMEGA]
            return (omega, omega_dot(y[THETA], omega, quasi_static_torque(u, omega), direction, engaged, side))
        return quasi_static_current

    def _compliant_rhs(self, u: float, mode: Mode):
        """dy/dt of the two-mass drive: the cam side as the rigid drive's under the shaft's torque, the rotor
        J_m omega_m' = c_m i - M_shaft, the twist's rate omega_m - omega (docs/model.md section 12)."""
        model, hybrid = self.model, self
        direction, engaged = mode.direction, mode.contact != 0
        side = mode.side if self.guide_side else 0.0
        stuck, has_current = mode.stuck, self.has_current

        def rhs(y):
            theta, omega, i, omega_m = y[THETA], y[OMEGA], y[CURRENT], y[OMEGA_M]
            if stuck:
                d_theta = d_omega = 0.0  # y[OMEGA] is 0 while stuck
            else:
                d_theta = omega
                d_omega = model.omega_dot(theta, omega, hybrid.drive_torque(y, u, omega), direction, engaged, side)
            shaft = hybrid.drive_torque(y, u, omega)
            d_omega_m = (hybrid.torque(y, u) - shaft) / model.J_m
            d_i = (u - model.R * i - model.c_e * omega_m) / model.L if has_current else 0.0
            return (d_theta, d_omega, d_i, omega_m - omega, d_omega_m)
        return rhs

    def stiffness_rate(self, y, mode: Mode, electrical: bool) -> float:
        """Largest rate [1/s] of the dynamics at y, for an explicit method's stability limit.

        The mechanical part: d(omega_dot)/d(omega) and the theta-omega oscillation
        that the profile's curvature makes, of frequency
        |omega| sqrt(m (s2^2 + |s1 s3|) / J). ``electrical`` False leaves out the
        pole of the current (a solver that integrates it exactly).
        """
        model = self.model
        s, s1, s2, s3 = model.program.derivatives(y[THETA])
        engaged = mode.contact != 0
        J = model.J_0 + (model.m * s1 * s1 if engaged else 0.0)
        omega = y[OMEGA]
        rate = 0.0
        if engaged:
            rate = (2.0 * model.m * abs(s1 * s2 * omega)
                    + abs(omega) * math.sqrt(model.m * J * (s2 * s2 + abs(s1 * s3)))) / J
        if self.compliant:  # the two-mass oscillation and its damping; the motor acts on the rotor alone
            inverse = 1.0 / model.J_m + 1.0 / J
            rate += math.sqrt(model.k_shaft * inverse) + model.d_shaft * inverse
            J = model.J_m
        if model.L > 0.0:
            if electrical:
                rate += self.motor.electrical_rate(J)
        else:
            rate += self.motor.electrical_rate(J)
        return rate

    def profile_rate(self, y) -> float:
        """|omega| / the profile's finest angular detail [1/s]: how fast the cam sweeps its features."""
        return abs(y[OMEGA]) / self.feature_angle

    def torque_gain(self, y, mode: Mode) -> float:
        """d(omega_dot)/d(i) = c_m / J [1/(A s2)] at y."""
        model = self.model
        s1 = model.program.derivatives(y[THETA])[1]
        return model.c_m / (model.J_0 + (model.m * s1 * s1 if mode.contact != 0 else 0.0))

    def first_breakpoint_passed(self, start: float, end: float) -> float | None:
        """The first profile breakpoint [rad] strictly between two angles, or None."""
        return self.model.program.first_breakpoint_passed(start, end)

    # ------------------------------------------------------------ events
    def event_names(self, mode: Mode) -> tuple[str, ...]:
        if mode.stuck:  # the torque on the held cam changes with a current or a shaft
            return (BREAK_AWAY,) if self.has_current or self.compliant else ()
        side = (SIDE,) if self.guide_side and mode.contact != 0 else ()
        if not self.backlash:
            return (STOP,) + side
        if mode.contact == 0:
            return (STOP, ENGAGE_UP, ENGAGE_DOWN)
        return (STOP, CONTACT) + side

    def event_values(self, y, u: float, mode: Mode) -> tuple[float, ...]:
        """Values of the active event functions (> 0: nothing happens)."""
        if mode.stuck:
            if not (self.has_current or self.compliant):
                return ()
            return (-self._breakaway_margin(y, u, mode),)
        stop = y[OMEGA] * mode.direction
        side = (self._side_value(y, u, mode),) if self.guide_side and mode.contact != 0 else ()
        if not self.backlash:
            return (stop,) + side
        s, s1, _, _ = self.model.program.derivatives(y[THETA])
        c = self.model.c
        if mode.contact == 0:
            return (stop, mode.s_free - (s - c), (s + c) - mode.s_free)
        # s1 times the direction held between events, not times omega: at a stop omega = 0 would
        # zero both functions at once (a tie the reference broke the other way); the stop decides there.
        return (stop, mode.contact * s1 * mode.direction) + side

    def _side_value(self, y, u: float, mode: Mode, side: float | None = None) -> float:
        """mode.side times the side force N_r [N] on that branch: > 0 while the branch holds."""
        side = mode.side if side is None else side
        return side * self.model.side_force(y[THETA], y[OMEGA], self.drive_torque(y, u, y[OMEGA]), mode.direction,
                                            side) \
            + SIDE_HYSTERESIS

    def _choose_side(self, y, u: float, mode: Mode) -> None:
        """The friction branch of the current state (where N_r = 0, the one it moves into)."""
        if self.guide_side and mode.contact != 0 and not mode.stuck:
            n_r = self.model.side_force(y[THETA], y[OMEGA], self.drive_torque(y, u, y[OMEGA]), mode.direction)
            if abs(n_r) > SIDE_HYSTERESIS:
                mode.side = -1.0 if n_r < 0.0 else 1.0

    def _engaged_toward(self, theta: float, mode: Mode, direction: float) -> bool:
        """Does the follower load the shaft when it starts toward ``direction`` from rest? Not when it is
        free in the gap, nor (backlash) where the cam would move away from it: the follower stays put."""
        if mode.contact == 0:
            return False
        if not self.backlash:
            return True
        s1 = self.model.program.derivatives(theta)[1]
        return not mode.contact * s1 * direction < 0.0

    def _breakaway_margin(self, y, u: float, mode: Mode) -> float:
        """> 0 when the shaft would start moving from rest [rad/s2], each direction with its own engagement."""
        model, torque = self.model, self.drive_torque(y, u, 0.0)
        forward = model.omega_dot(y[THETA], 0.0, torque, 1.0, self._engaged_toward(y[THETA], mode, 1.0))
        backward = -model.omega_dot(y[THETA], 0.0, torque, -1.0, self._engaged_toward(y[THETA], mode, -1.0))
        return max(forward, backward)

    def apply_event(self, y, u: float, mode: Mode, name: str) -> None:
        """The transition of event ``name``, in place on y and mode."""
        model = self.model
        if name == STOP:
            y[OMEGA] = 0.0
            mode.stuck = True
            self.settle(y, u, mode)
        elif name == BREAK_AWAY:
            # The located zero of the margin: the torque is at the threshold
            # (margin >= 0, often exactly 0 there), so the shaft starts now.
            self.settle(y, u, mode, at_threshold=True)
        elif name == SIDE:
            mode.side = -mode.side  # N_r passed through zero: the other friction branch
        elif name == CONTACT:
            s = model.program.derivatives(y[THETA])[0]
            mode.s_free = s - model.c * mode.contact
            mode.contact = 0
        else:
            mode.contact = 1 if name == ENGAGE_UP else -1
            s1 = model.program.derivatives(y[THETA])[1]
            # Plastic impact: generalised momentum J_0 omega (+ m s' v = 0 before) is kept; a compliant
            # shaft's rotor is not in it (the shaft's torque is finite).
            y[OMEGA] = model.J_0 * y[OMEGA] / (model.J_0 + model.m * s1 * s1)
            self._choose_side(y, u, mode)

    def settle(self, y, u: float, mode: Mode, at_threshold: bool = False) -> None:
        """At rest: stay stuck or start in the direction the torques allow; then the friction branch."""
        self._settle_motion(y, u, mode, at_threshold)
        self._choose_side(y, u, mode)

    def _settle_motion(self, y, u: float, mode: Mode, at_threshold: bool = False) -> None:
        """At rest: stay stuck or start in the direction the torques allow.

        ``at_threshold``: called at a located break-away, where the margin is
        zero to rounding; the shaft then starts toward the larger acceleration
        instead of waiting for the next communication step.
        """
        model = self.model
        torque = self.drive_torque(y, u, y[OMEGA])
        if not mode.stuck:
            if y[OMEGA] != 0.0:
                return
            # At rest but marked as moving (it started under other inputs, or at
            # a break-away): it goes on unless it now accelerates backwards.
            engaged = self._engaged_toward(y[THETA], mode, mode.direction)
            if mode.direction * model.omega_dot(y[THETA], 0.0, torque, mode.direction, engaged) >= 0.0:
                return
            mode.stuck = True
        # Each direction with the follower as it would be there: the break-away event's margin is the
        # same test, so a located break-away always starts the shaft (an event that fired without effect
        # fired again at once: with gravity, backlash and L > 0 the engine chattered at a stall).
        forward_engaged = self._engaged_toward(y[THETA], mode, 1.0)
        backward_engaged = self._engaged_toward(y[THETA], mode, -1.0)
        direction = model.breakaway_direction(y[THETA], torque, forward_engaged, backward_engaged)
        if direction == 0.0 and at_threshold:
            forward = model.omega_dot(y[THETA], 0.0, torque, 1.0, forward_engaged)
            backward = -model.omega_dot(y[THETA], 0.0, torque, -1.0, backward_engaged)
            if forward == backward and (self.has_current or self.compliant):
                # A tie (no shaft friction, zero torque as the current or the twist passes through 0):
                # the shaft goes where the torque is heading. Taking +1 here made the reference
                # chatter forever between the break-away and a stop at one instant.
                rate = y[OMEGA_M] if self.compliant else self.motor.current_rate(u, y[CURRENT], 0.0)
                if self.compliant and rate == 0.0:  # the rotor at rest too: where its acceleration takes the twist
                    rate = self.torque(y, u) - torque
                if self.compliant and rate == 0.0 and self.has_current:  # no torque yet: where the current heads
                    rate = self.motor.current_rate(u, y[CURRENT], 0.0)
                direction = 1.0 if rate > 0.0 else (-1.0 if rate < 0.0 else 0.0)
            else:
                direction = 1.0 if forward >= backward else -1.0
        if direction == 0.0:
            return
        leaves = False
        if self.backlash and mode.contact != 0:
            s, s1, _, _ = model.program.derivatives(y[THETA])
            leaves = mode.contact * s1 * direction < 0.0  # the cam would leave the follower
            # Starting that way is consistent only if the shaft, rid of the follower, still
            # accelerates that way: else (gravity pulled the cam back, but without the
            # follower the motor pulls it forward) it stays at rest instead of chattering.
            if leaves and direction * model.omega_dot(y[THETA], 0.0, torque, direction, False) <= 0.0:
                return
        mode.stuck = False
        mode.direction = direction
        if leaves:
            mode.s_free = s - model.c * mode.contact
            mode.contact = 0

    # ----------------------------------------------------------- outputs
    def outputs(self, y, u: float, mode: Mode, omega_dot: float | None = None) -> dict[str, float]:
        """Every output of the drive at state y (SI units).

        ``omega_dot``: the angular acceleration at y when the caller has it
        already (the last stage of a first-same-as-last step), else computed.
        """
        model = self.model
        theta, omega = y[THETA], y[OMEGA]
        i = self.current(y, u)
        engaged = mode.contact != 0
        if mode.stuck:
            load = model.load(theta, 0.0, 0.0, 0.0, engaged)
            # static friction takes whatever the motor (or the shaft) applies
            load.M = self.drive_torque(y, u, 0.0) if self.compliant else model.c_m * i
            load.v = load.a = 0.0
        else:
            if omega_dot is None:
                omega_dot = self.derivative(y, u, mode)[1]
            load = model.load(theta, omega, omega_dot, mode.direction, engaged)
        s = load.s_cam - model.c * mode.contact if engaged else mode.s_free
        rotor = dict(theta_m=theta, omega_m=omega, M_shaft=0.0)  # rigid: the rotor turns with the cam
        J = load.J
        if self.compliant:  # J counts the rotor too, as a rigid drive's does
            J = load.J + model.J_m
            rotor = dict(theta_m=theta + y[TWIST], omega_m=y[OMEGA_M],
                         M_shaft=self.drive_torque(y, u, 0.0 if mode.stuck else omega))
        return output_record(omega=omega, theta=theta, s=s, i=i, M=load.M, J=J, v=load.v, a=load.a,
                             alpha=load.alpha, s_cam=load.s_cam, voltage=u, N_contact=load.N, **rotor)
