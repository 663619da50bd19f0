"""The reference of the follower as a body of its own on a cam at imposed speed (docs/model.md section 13).

The state (theta, s, v): theta under the imposed speed, the follower's (s, v) under spring, gravity along the stroke
and guide friction while it flies, through the one hybrid loop (hybrid.py) with the events of docs/model.md 13.7:
lift-off (the flank's force reaches 0: ``SpeedFollower.held``), touch-down (a gap reaches -TOUCH), halt in flight
(v = 0, where the friction turns) and, at an input break, a step of omega_ref. Rows are the speed drive's outputs with
the follower's own s, v, a and N_contact [N] (0 in flight), plus contact (+1, -1, 0 off the flanks) and impacts (how
many so far).
"""
from __future__ import annotations

import numpy as np

from ..physics.modes import Event, Follower, Mode, Shaft
from ..physics.signals import Signal
from ..physics.speed_follower import SpeedFollower
from .hybrid import HybridRun, event, piece_input

# m: a touch-down is located where the gap reaches -TOUCH (1 pm), and the follower is then set on the flank. Just
# after a lift-off the gap grows as t^3 (gap, its rate and its acceleration are all 0 there), so a gap of exactly 0
# would meet the integration's rounding (atol 1e-13 m) and land the follower again at once, without end.
TOUCH = 1e-12
# rad: the cam's turn in one integration step at most while the follower flies. A flight without a spring is a
# polynomial in time, which DOP853 integrates exactly in one step of any length: without a bound, one step could
# hold a gap's crossing and its return, and the event (checked at the steps' ends) would be missed.
FLIGHT_ANGLE = 1e-2


def flying(body, y: list, v: int = 2) -> Follower:
    """FLIGHT, or HALTED where the flying follower (velocity y[v]) is at rest and held (``body.direction`` 0)."""
    return Follower.HALTED if body.direction(y[v - 1], y[v]) == 0.0 else Follower.FLIGHT


def speed_motion(omega: float, omega_dot: float, t: float) -> float:
    """The way the cam moves just before t [s] at the speed omega [rad/s] and acceleration omega_dot [rad/s2] of the
    interval ending there: omega, and where omega is 0 (to within omega_dot times the rounding of t, 1e-12 max(1, t),
    as the C engine's speed.c) -omega_dot, the way it came into the stop (the left limit, docs/model.md 8.1)."""
    return omega if abs(omega) > 1e-12 * max(1.0, abs(t)) * abs(omega_dot) else -omega_dot


class FollowerRun(HybridRun):
    """One run of the speed drive with the follower's own state y = (theta, s, v)."""

    label = "follower reference"
    BODY = SpeedFollower  # the follower's equations (physics.kind_follower's for another kind)

    def __init__(self, model, omega_ref: Signal, rtol: float, atol: float) -> None:
        self.body = self.BODY(model)
        self.omega_ref = omega_ref
        self.rtol, self.atol = rtol, atol
        self.impacts: list[tuple[float, float, float]] = []  # (t [s], w before, w after [m/s])

    def _speed(self, t: float) -> tuple[float, float]:
        return self.omega_ref.value(t), self.omega_ref.slope(t)

    def _holds(self, theta: float, omega: float, omega_dot: float, side: float) -> float:
        """N, > 0 where the flank ``side`` holds the follower at the start (SpeedFollower.held)."""
        return self.body.held(theta, omega, omega_dot, side)

    def _start(self, y: list, omega: float) -> list:
        """The starting state y = (theta, s, v) with the states a subclass carries after them (none here)."""
        return y

    def run(self, grid: np.ndarray, theta0: float) -> dict[str, np.ndarray]:
        """Rows on ``grid`` [s] from theta0 [rad]: on the +1 flank if it holds the follower, else on -1 (groove),
        else flying from the +1 flank."""
        body, t = self.body, float(grid[0])
        omega, omega_dot = self._speed(t)
        flanks = (1.0, -1.0) if body.two_sided else (1.0,)
        contact = next((side for side in flanks if self._holds(theta0, omega, omega_dot, side) >= 0.0), 0.0)
        s, s1, _, _ = body.flank(theta0, contact or 1.0)
        y = self._start([theta0, s, s1 * omega], omega)
        mode = Mode(Follower.flank(contact) if contact else flying(body, y))
        return self.pieces(grid, t, y, mode, sorted(b for b in self.omega_ref.breaks if t < b < float(grid[-1])))

    def _piece(self, t: float, y: list, mode: Mode) -> tuple[list, object, dict]:
        body, speed = self.body, piece_input(self.omega_ref, self.piece_end)
        options = {"method": "DOP853", "atol": self.atol}
        if mode.follower.on_flank:
            contact = mode.contact

            def follow(t, y):  # (s, v) ride on the flank; only theta matters, s and v are reset from the cam
                omega, omega_dot = speed(t)
                _, s1, s2, _ = body.flank(y[0], contact)
                return [omega, s1 * omega, s2 * omega * omega + s1 * omega_dot]
            return [event(Event.LIFT_OFF, lambda t, y: body.held(y[0], *speed(t), contact))], follow, options
        omega = max(abs(w) for w in self.omega_ref.values)  # rad/s: the fastest the cam turns (a bound in any piece)
        if omega > 0.0:
            options["max_step"] = FLIGHT_ANGLE / omega
        sigma = body.direction(y[1], y[2]) if mode.follower is Follower.FLIGHT else 0.0

        def fly(t, y):
            return [speed(t)[0], y[2], body.free_acceleration(y[1], sigma)]
        return flight_events(body, lambda y: body.gaps(y[0], y[1]), 2, sigma), fly, options

    # ------------------------------------------------------------- the transitions (docs/model.md 13.7)
    def _lift_off(self, t: float, y: list, mode: Mode, kind: Event) -> tuple[Mode, list]:
        s, s1, _, _ = self.body.flank(y[0], mode.contact)
        y = [y[0], s, s1 * self._speed(t)[0], *y[3:]]
        return Mode(flying(self.body, y), mode.shaft, mode.direction), y

    def _halt(self, t: float, y: list, mode: Mode, kind: Event) -> tuple[Mode, list]:
        y = [y[0], y[1], 0.0, *y[3:]]
        return Mode(flying(self.body, y), mode.shaft, mode.direction), y

    def _touch(self, t: float, y: list, mode: Mode, kind: Event) -> tuple[Mode, list]:
        omega, omega_dot, flank = *self._speed(t), 1.0 if kind is Event.TOUCH_LOWER else -1.0
        return self._struck(t, y, mode, flank, self.body.land(y[0], omega, omega_dot, y[2], flank))


    def _struck(self, t: float, y: list, mode: Mode, flank: float, landed: tuple) -> tuple[Mode, list]:
        """The state after an impact on ``flank`` (``landed``: SpeedFollower.land's answer), counted."""
        body = self.body
        omega, omega_dot = self._speed(t)
        after, v, _ = landed
        s, s1, _, _ = body.flank(y[0], flank)
        self._impact(t, y[2] - s1 * omega, v - s1 * omega, after == 0.0, body.acceleration_scale(y[0], omega, omega_dot))
        y = [y[0], s, v, *y[3:]]
        return Mode(Follower.flank(after) if after else flying(body, y), mode.shaft, mode.direction), y

    def _settle(self, t: float, y: list, mode: Mode, after_event: bool) -> tuple[Mode, list]:
        """At every restart: the shaft's mode from the input, the follower off the flanks in flight or halted, on a
        flank the step of omega_ref's transition (none where omega did not jump)."""
        omega = self._speed(t)[0]
        mode = Mode(mode.follower, Shaft.TURNING if omega else Shaft.STOPPED, -1.0 if omega < 0.0 else 1.0)
        if not mode.follower.on_flank:
            return Mode(flying(self.body, y), mode.shaft, mode.direction), y
        return self._speed_step(t, y, mode, Event.SPEED_STEP)

    def _speed_step(self, t: float, y: list, mode: Mode, kind: Event) -> tuple[Mode, list]:
        """The flank's speed jumped, the follower's did not: a lift-off or an impact (SpeedFollower.speed_step); then
        a lift-off whose function is already < 0 (s'' jumped at a breakpoint or the input did)."""
        (omega, omega_dot), contact = self._speed(t), mode.contact
        after, v, hit = self.body.speed_step(y[0], omega, omega_dot, y[2], contact)
        if hit is not None:
            return self._struck(t, y, mode, contact, (after, v, hit))
        if after == 0.0:   # the flank moves away faster than the follower: it flies on with its speed
            y = [y[0], self.body.flank(y[0], contact)[0], v, *y[3:]]
            return Mode(flying(self.body, y), mode.shaft, mode.direction), y
        if self.body.held(y[0], omega, omega_dot, contact) < 0.0:
            return self._lift_off(t, y, mode, Event.LIFT_OFF)
        s, s1, _, _ = self.body.flank(y[0], contact)
        return mode, [y[0], s, s1 * omega, *y[3:]]

    TRANSITIONS = {Event.LIFT_OFF: _lift_off, Event.HALT: _halt, Event.TOUCH_LOWER: _touch, Event.TOUCH_UPPER: _touch,
                   Event.SPEED_STEP: _speed_step}

    def _row(self, t: float, y, mode: Mode, left: bool) -> dict[str, float]:
        # at an input's kink or jump its left limit, the interval ending at t (docs/model.md 8.1); at 0 the first piece
        omega = self.omega_ref.left_value(t) if t > 0.0 else self.omega_ref.value(t)
        omega_dot = self.omega_ref.left_slope(t) if t > 0.0 else self.omega_ref.slope(t)
        motion = omega if t == 0.0 else speed_motion(omega, omega_dot, t)   # a stop at t still moves (left limit)
        row = self.body.outputs(float(y[0]), omega, omega_dot, float(y[1]), float(y[2]), mode.contact,
                                1.0 if motion > 0.0 else (-1.0 if motion < 0.0 else 0.0))
        row["impacts"] = float(len(self.impacts))
        return row


def flight_events(body, gaps, v: int, sigma: float) -> list:
    """The events in flight: touch-down on each flank (``gaps(y)``: the gaps to the +1 and -1 flanks [m]) where
    its gap reaches -TOUCH, and the halt where the velocity y[v] turns under guide friction (sigma != 0)."""
    events = [event(Event.TOUCH_LOWER, lambda t, y: gaps(y)[0] + TOUCH)]
    if body.two_sided:
        events.append(event(Event.TOUCH_UPPER, lambda t, y: gaps(y)[1] + TOUCH))
    if body.f0 > 0.0 and sigma != 0.0:  # the friction's direction turns where v does
        events.append(event(Event.HALT, lambda t, y: sigma * y[v]))
    return events


def follower_speed_reference(model, grid: np.ndarray, omega_ref: Signal, rtol: float, atol: float) -> dict[str, np.ndarray]:
    """The speed drive with the follower's own state (closures 'form' and 'spring'), on the output grid."""
    return FollowerRun(model, omega_ref, rtol, atol).run(grid, model.params["theta0"])
