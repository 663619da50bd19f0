"""The consistent cam drive as a hybrid system: continuous states, modes, events.

Continuous state y = (theta [rad], omega [rad/s]) and, when L > 0, i [A].
Discrete mode: stuck (shaft held by static friction), direction of motion,
backlash contact (+1: the cam drives the follower up, -1: down, 0: free in the
gap) and the follower's position while free. Both the FMU stepper and the
scipy reference integrate ``derivative`` and stop at the zeros of
``event_values``: one physics code, two integrators (MODEL.md sections 5-6).

Events are functions that are > 0 while nothing happens; a crossing to <= 0
triggers ``apply_event`` with the index of the function.
"""
from __future__ import annotations

import math
from dataclasses import asdict, dataclass
from typing import Any

from .drive_model import DriveModel, LoadState

STOP, CONTACT, ENGAGE_UP, ENGAGE_DOWN, BREAK_AWAY = "stop", "contact", "engage_up", "engage_down", "break_away"


@dataclass
class Mode:
    """Discrete state. ``contact`` is +1 with no backlash (always engaged)."""

    stuck: bool = False
    direction: float = 1.0  # sgn(omega) while moving
    contact: int = 1
    s_free: float = 0.0  # m, follower position while contact == 0

    def copy(self) -> "Mode":
        return Mode(self.stuck, self.direction, self.contact, self.s_free)

    def to_dict(self) -> dict[str, Any]:
        return asdict(self)


class HybridDrive:
    """Consistent formulation of the drive under a voltage input u [V]."""

    def __init__(self, model: DriveModel) -> None:
        self.model = model
        self.has_current = model.L > 0.0
        self.backlash = model.c > 0.0
        self.size = 3 if self.has_current else 2

    # ------------------------------------------------------------ set-up
    def initial(self, theta0: float, omega0: float, i0: float) -> tuple[list[float], Mode]:
        """Initial state and mode (from rest: stuck until ``settle`` lets it go)."""
        y = [theta0, omega0, i0][: self.size]
        mode = Mode(stuck=omega0 == 0.0, direction=1.0 if omega0 >= 0.0 else -1.0)
        if self.backlash:
            # The paper's step 1: the follower starts where the cam is, centred in the gap.
            mode.contact = 0
            mode.s_free = self.model.program.derivatives(theta0)[0]
        return y, mode

    def torque(self, y, u: float) -> float:
        """Motor torque c_m i [N m]."""
        m = self.model
        if self.has_current:
            return m.c_m * y[2]
        return m.c_m * (u - m.c_e * y[1]) / m.R

    def current(self, y, u: float) -> float:
        m = self.model
        return y[2] if self.has_current else (u - m.c_e * y[1]) / m.R

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
        model = self.model
        R, L, c_e, c_m = model.R, model.L, model.c_e, model.c_m
        omega_dot = model.omega_dot
        direction, engaged = mode.direction, mode.contact != 0
        if self.has_current:
            if mode.stuck:
                return lambda y: (0.0, 0.0, (u - R * y[2] - c_e * y[1]) / L)

            def with_current(y):
                omega, i = y[1], y[2]
                return (omega, omega_dot(y[0], omega, c_m * i, direction, engaged), (u - R * i - c_e * omega) / L)
            return with_current
        if mode.stuck:
            return lambda y: (0.0, 0.0)

        def quasi_static_current(y):
            omega = y[1]
            return (omega, omega_dot(y[0], omega, c_m * (u - c_e * omega) / R, direction, engaged))
        return quasi_static_current

    # ------------------------------------------------------------ events
    def event_names(self, mode: Mode) -> tuple[str, ...]:
        if mode.stuck:
            return (BREAK_AWAY,) if self.has_current else ()
        if not self.backlash:
            return (STOP,)
        if mode.contact == 0:
            return (STOP, ENGAGE_UP, ENGAGE_DOWN)
        return (STOP, CONTACT)

    def event_values(self, y, u: float, mode: Mode) -> tuple[float, ...]:
        """Values of the active event functions (> 0: nothing happens)."""
        if mode.stuck:
            if not self.has_current:
                return ()
            return (-self._breakaway_margin(y, u, mode),)
        stop = y[1] * mode.direction
        if not self.backlash:
            return (stop,)
        s, s1, _, _ = self.model.program.derivatives(y[0])
        c = self.model.c
        if mode.contact == 0:
            return (stop, mode.s_free - (s - c), (s + c) - mode.s_free)
        return (stop, mode.contact * s1 * y[1])

    def _breakaway_margin(self, y, u: float, mode: Mode) -> float:
        """> 0 when the shaft would start moving from rest [rad/s2]."""
        model, torque, engaged = self.model, self.torque(y, u), mode.contact != 0
        forward = model.omega_dot(y[0], 0.0, torque, 1.0, engaged)
        backward = -model.omega_dot(y[0], 0.0, torque, -1.0, engaged)
        return max(forward, backward)

    def apply_event(self, y, u: float, mode: Mode, name: str) -> None:
        """The transition of event ``name``, in place on y and mode."""
        model = self.model
        if name == STOP:
            y[1] = 0.0
            mode.stuck = True
            self.settle(y, u, mode)
        elif name == BREAK_AWAY:
            # The located zero of the margin: the torque is at the threshold
            # (margin >= 0, often exactly 0 there), so the shaft starts now.
            self.settle(y, u, mode, at_threshold=True)
        elif name == CONTACT:
            s = model.program.derivatives(y[0])[0]
            mode.s_free = s - model.c * mode.contact
            mode.contact = 0
        else:
            mode.contact = 1 if name == ENGAGE_UP else -1
            s1 = model.program.derivatives(y[0])[1]
            # Plastic impact: generalised momentum J_m omega (+ m s' v = 0 before) is kept.
            y[1] = model.J_m * y[1] / (model.J_m + model.m * s1 * s1)

    def settle(self, y, u: float, mode: Mode, at_threshold: bool = False) -> None:
        """At rest: stay stuck or start in the direction the torques allow.

        ``at_threshold``: called at a located break-away, where the margin is
        zero to rounding; the shaft then starts toward the larger acceleration
        instead of waiting for the next communication step.
        """
        model = self.model
        torque, engaged = self.torque(y, u), mode.contact != 0
        if not mode.stuck:
            if y[1] != 0.0:
                return
            # At rest but marked as moving (it started under other inputs, or at
            # a break-away): it goes on unless it now accelerates backwards.
            if mode.direction * model.omega_dot(y[0], 0.0, torque, mode.direction, engaged) >= 0.0:
                return
            mode.stuck = True
        direction = model.breakaway_direction(y[0], torque, engaged)
        if direction == 0.0 and at_threshold:
            forward = model.omega_dot(y[0], 0.0, torque, 1.0, engaged)
            backward = -model.omega_dot(y[0], 0.0, torque, -1.0, engaged)
            direction = 1.0 if forward >= backward else -1.0
        if direction == 0.0:
            return
        mode.stuck = False
        mode.direction = direction
        if self.backlash and mode.contact != 0:
            s, s1, _, _ = model.program.derivatives(y[0])
            if mode.contact * s1 * direction < 0.0:  # the cam leaves the follower
                mode.s_free = s - model.c * mode.contact
                mode.contact = 0

    # ----------------------------------------------------------- outputs
    def outputs(self, y, u: float, mode: Mode, omega_dot: float | None = None) -> dict[str, float]:
        """Every output of the drive at state y (SI units).

        ``omega_dot``: the angular acceleration at y when the caller has it
        already (the last stage of a first-same-as-last step), else computed.
        """
        model = self.model
        theta, omega = y[0], y[1]
        i = self.current(y, u)
        engaged = mode.contact != 0
        if mode.stuck:
            load = model.load(theta, 0.0, 0.0, 0.0, engaged)
            load.M = model.c_m * i  # static friction takes whatever the motor applies
            load.v = load.a = 0.0
        else:
            if omega_dot is None:
                omega_dot = self.derivative(y, u, mode)[1]
            load = model.load(theta, omega, omega_dot, mode.direction, engaged)
        s = load.s_cam - model.c * mode.contact if engaged else mode.s_free
        return _outputs(theta, omega, i, s, load.s_cam, load, u)


def _outputs(theta: float, omega: float, i: float, s: float, s_cam: float, load: LoadState, voltage: float) -> dict[str, float]:
    return {
        "omega": omega, "theta": theta, "s": s, "i": i, "M": load.M, "J": load.J,
        "v": load.v, "a": load.a, "alpha": load.alpha, "s_cam": s_cam, "voltage": voltage,
    }


def speed_drive_outputs(model: DriveModel, theta: float, omega: float, omega_dot: float, s: float, engaged: bool) -> dict[str, float]:
    """Speed drive: torque, inertia, current and voltage needed for a given motion.

    c_m i = J_m omega_dot + M (consistent formulation); the voltage adds
    L di/dt, with di/dt = omega dM/dtheta at constant speed (central difference,
    1e-6 rad).
    """
    direction = 1.0 if omega > 0.0 else (-1.0 if omega < 0.0 else 0.0)
    load = model.load(theta, omega, omega_dot, direction, engaged)
    i = (model.J_m * omega_dot + load.M) / model.c_m
    voltage = model.R * i + model.c_e * omega
    if model.L > 0.0 and omega != 0.0:
        d = 1e-6
        dM = (model.load(theta + d, omega, omega_dot, direction, engaged).M
              - model.load(theta - d, omega, omega_dot, direction, engaged).M) / (2 * d)
        voltage += model.L * omega * dM / model.c_m
    s_cam = model.program.derivatives(theta)[0]
    return _outputs(theta, omega, i, s, s_cam, load, voltage)


def crossed(points, start: float, end: float) -> list[float]:
    """Angles of the periodic points (in [0, 2 pi)) passed going from start to end [rad], in order."""
    two_pi = 2.0 * math.pi
    lo, hi = min(start, end), max(start, end)
    out = []
    for p in points:
        k = math.ceil((lo - p) / two_pi)
        angle = p + k * two_pi
        while angle < hi:
            if angle > lo:
                out.append(angle)
            angle += two_pi
    out.sort(reverse=end < start)
    return out


def follower_along(program, s: float, start: float, end: float, c: float) -> float:
    """Follower position [m] after the cam turns from start to end [rad] with play c [m].

    The play operator sees every breakpoint passed on the way, where the
    extrema of s_cam lie, not only the end point (speed drive).
    """
    if c == 0.0:
        return program.derivatives(end)[0]
    for angle in crossed(program.breakpoints(), start, end):
        s = play(program.derivatives(angle)[0], s, c)
    return play(program.derivatives(end)[0], s, c)


def speed_engaged(program, theta: float, s: float, omega: float, c: float) -> bool:
    """Is the follower at s [m] dragged by the cam at theta moving at omega (not free in the gap)?"""
    if c == 0.0:
        return True
    s_cam, s1, _, _ = program.derivatives(theta)
    gap = s_cam - s
    return abs(gap) >= c * (1.0 - 1e-9) and gap * s1 * omega > 0.0


def play(s_cam: float, s_prev: float, c: float) -> float:
    """Backlash play operator (paper eqs. 6-8, continuous form): follower position [m]."""
    if s_cam > s_prev + c:
        return s_cam - c
    if s_cam < s_prev - c:
        return s_cam + c
    return s_prev


