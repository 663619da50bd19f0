"""The reference of the follower as a body of its own on a cam at imposed speed (docs/model.md section 13).

scipy's solve_ivp integrates the state (theta, s, v) at tight tolerances: theta under the imposed speed,
the follower's (s, v) under spring, gravity along the stroke and guide friction while it flies. Terminal
events stop it at each lift-off (the flank's force reaches 0: ``SpeedFollower.held``), touch-down (a gap
reaches 0), halt in flight (v = 0, where the friction turns) and input break; the transition is applied at
the located time and the integration restarts there. Rows are the speed drive's outputs with the
follower's own s, v, a and N_contact [N] (0 in flight), plus contact (+1, -1, 0 in flight) and impacts (how
many so far).
"""
from __future__ import annotations

import math
from typing import Callable

import numpy as np
from scipy.integrate import solve_ivp

from ..physics.signals import Signal
from ..physics.speed_follower import SpeedFollower

# Events at one instant in a row before the run is refused (each transition changes the mode; a cycle means
# a model error, never a hang).
MAX_STALL = 1000
# m: a touch-down is located where the gap reaches -TOUCH (1 pm), and the follower is then set on the flank. Just
# after a lift-off the gap grows as t^3 (gap, its rate and its acceleration are all 0 there), so a gap of exactly 0
# would meet the integration's rounding (atol 1e-13 m) and land the follower again at once, without end.
TOUCH = 1e-12
# rad: the cam's turn in one integration step at most while the follower flies. A flight without a spring is a
# polynomial in time, which DOP853 integrates exactly in one step of any length: without a bound, one step could
# hold a gap's crossing and its return, and the event (checked at the steps' ends) would be missed.
FLIGHT_ANGLE = 1e-2


def next_breakpoint(breakpoints: list[float], theta: float, direction: float) -> float:
    """The first of the profile's breakpoints [rad] (sorted over one turn, with 0 and 2 pi) strictly ahead of theta
    [rad] in the direction of motion."""
    two_pi = 2.0 * math.pi
    base = math.floor(theta / two_pi) * two_pi
    local = theta - base
    eps = 1e-12 * max(1.0, abs(theta))
    if direction > 0:
        for b in breakpoints:
            if b > local + eps:
                return base + b
        return base + two_pi + breakpoints[1]
    for b in reversed(breakpoints):
        if b < local - eps:
            return base + b
    return base - two_pi + breakpoints[-2]


class PieceRun:
    """A hybrid run integrated piece by piece with solve_ivp (the follower's runs here and in voltage_flight.py).

    Subclasses give ``_piece`` (events, right-hand side and solve_ivp options of the mode), ``_settle``,
    ``_transition``, ``_row`` and set ``rtol``, ``rebound`` (s, the first piece after a rebound kept shorter than the
    bounce, or 0) and ``label`` (the errors' prefix).
    """

    label = "follower reference"

    def pieces(self, grid: np.ndarray, t: float, y: list, contact: float, breaks: list[float]) -> dict[str, np.ndarray]:
        """Rows on ``grid`` from (t, y, contact), stopping at each event and input break [s]."""
        stop = float(grid[-1])
        breaks = breaks + [stop]
        rows, k_out, stalled, t_last = [], 0, 0, -math.inf
        while True:
            while k_out < len(grid) and grid[k_out] <= t + 1e-15 * max(1.0, t):
                rows.append(self._row(float(grid[k_out]), y, contact))
                k_out += 1
            if t >= stop:
                break
            contact, y = self._settle(t, y, contact)
            t_end = next(b for b in breaks if b > t + 1e-15 * max(1.0, t))
            self.piece_end = t_end   # the piece's input up to t_end is its own (piece_input)
            events, rhs, options = self._piece(t, y, contact)
            if self.rebound > 0.0:  # the first piece after a rebound is shorter than the bounce it starts
                t_end = min(t_end, t + self.rebound)
                options["max_step"] = min(options.get("max_step", math.inf), self.rebound / 8.0)
                self.rebound = 0.0
            sol = solve_ivp(rhs, (t, t_end), y, rtol=self.rtol, events=events, dense_output=True, **options)
            if sol.status < 0:
                raise RuntimeError(f"{self.label}: {sol.message}")
            t_new = float(sol.t[-1])
            while k_out < len(grid) and grid[k_out] < t_new:  # outputs inside this piece, from its dense output
                rows.append(self._row(float(grid[k_out]), list(sol.sol(grid[k_out])), contact))
                k_out += 1
            y = list(sol.y[:, -1])
            if sol.status == 1:
                fired = next(j for j, te in enumerate(sol.t_events) if len(te))
                stalled = stalled + 1 if t_new - t_last <= 1e-14 * max(1.0, t_new) else 0
                if stalled > MAX_STALL:
                    raise RuntimeError(f"{self.label}: {MAX_STALL} events at t = {t_new!r} s without end")
                t_last = t_new
                contact, y = self._transition(t_new, y, contact, events[fired].kind)
            t = t_new
        result = {"time": grid.copy()}
        for name in rows[0]:
            result[name] = np.array([row[name] for row in rows])
        return result


def speed_motion(omega: float, omega_dot: float, t: float) -> float:
    """The way the cam moves just before t [s] at the speed omega [rad/s] and acceleration omega_dot [rad/s2] of the
    interval ending there: omega, and where omega is 0 (to within omega_dot times the rounding of t, 1e-12 max(1, t),
    as the C engine's speed.c) -omega_dot, the way it came into the stop (the left limit, docs/model.md 8.1)."""
    return omega if abs(omega) > 1e-12 * max(1.0, abs(t)) * abs(omega_dot) else -omega_dot


def piece_input(signal: Signal, end: float) -> Callable[[float], tuple[float, float]]:
    """(value, slope) of ``signal`` as a function of t within a piece that ends at ``end`` [s]: at the end, an input's
    break, the piece's own (the left limit). solve_ivp evaluates the right-hand side and the events at the end point;
    with the value after the break there, an event that the break itself makes (a break-away at a step of u) was
    located a rounding before the break and applied there with the input before it, 1000 times over."""
    def at(t: float) -> tuple[float, float]:
        if t < end:
            return signal.value(t), signal.slope(t)
        return signal.left_value(end), signal.left_slope(end)
    return at


class FollowerRun(PieceRun):
    """One run of the speed drive with the follower's own state."""

    def __init__(self, model, omega_ref: Signal, rtol: float, atol: float) -> None:
        self.body = SpeedFollower(model)
        self.omega_ref = omega_ref
        self.rtol, self.atol = rtol, atol
        self.impacts: list[tuple[float, float, float]] = []  # (t [s], w before, w after [m/s])
        # s: a time shorter than the flight the last rebound starts, or 0. A step of the integrator holding the whole
        # bounce would see the gap <= 0 at its end and locate the touch-down at its start, where the gap is 0.
        self.rebound = 0.0

    def _speed(self, t: float) -> tuple[float, float]:
        return self.omega_ref.value(t), self.omega_ref.slope(t)

    def _start_contact(self, t: float, theta: float, s: float, v: float) -> float:
        """The mode at the start: on the +1 flank if it holds the follower, else on -1 (groove), else flying."""
        omega, omega_dot = self._speed(t)
        for contact in (1.0, -1.0) if self.body.two_sided else (1.0,):
            if self.body.held(theta, omega, omega_dot, contact) >= 0.0:
                return contact
        return 0.0

    def run(self, grid: np.ndarray, theta0: float) -> dict[str, np.ndarray]:
        body = self.body
        t = float(grid[0])
        s_cam, s1, _, _ = body.program.derivatives(theta0)
        omega = self.omega_ref.value(t)
        contact = self._start_contact(t, theta0, s_cam, s1 * omega)
        side = contact if contact != 0.0 else 1.0  # which flank the follower starts on (+1 if flying)
        y = [theta0, s_cam - side * body.c, s1 * omega]
        breaks = sorted(b for b in self.omega_ref.breaks if t < b < float(grid[-1]))
        return self.pieces(grid, t, y, contact, breaks)

    def _piece(self, t: float, y: list, contact: float) -> tuple[list, object, dict]:
        sigma = self._direction(y)
        options = {"method": "DOP853", "atol": self.atol}
        omega = max(abs(w) for w in self.omega_ref.values)  # rad/s: the fastest the cam turns (a bound in any piece)
        if contact == 0.0 and omega > 0.0:
            options["max_step"] = FLIGHT_ANGLE / omega
        return self._events(contact, sigma), self._rhs(contact, sigma), options

    # ------------------------------------------------------------- the hybrid system
    def _direction(self, y: list) -> float:
        """The sign of the follower's velocity over the next piece of flight: sgn(v), or at a halt the way the net
        force pushes it beyond the guide's static friction (0: held)."""
        if y[2] != 0.0:
            return 1.0 if y[2] > 0.0 else -1.0
        a = self.body.free_acceleration(y[1], 0.0) if self.body.m > 0.0 else 0.0
        return 1.0 if a > 0.0 else (-1.0 if a < 0.0 else 0.0)

    def _rhs(self, contact: float, sigma: float):
        body, speed = self.body, piece_input(self.omega_ref, self.piece_end)
        if contact != 0.0:
            def follow(t, y):  # (s, v) ride on the flank; only theta matters, s and v are reset from the cam
                omega, omega_dot = speed(t)
                _, s1, s2, _ = body.program.derivatives(y[0])
                return [omega, s1 * omega, s2 * omega * omega + s1 * omega_dot]
            return follow

        def fly(t, y):
            return [speed(t)[0], y[2], body.free_acceleration(y[1], sigma)]
        return fly

    def _events(self, contact: float, sigma: float) -> list:
        body, speed = self.body, piece_input(self.omega_ref, self.piece_end)
        events = []

        def add(kind: str, fn) -> None:
            fn.terminal, fn.direction, fn.kind = True, -1, kind
            events.append(fn)

        if contact != 0.0:
            add("lift-off", lambda t, y: body.held(y[0], *speed(t), contact))
            return events
        add("touch-down +1", lambda t, y: body.gaps(y[0], y[1])[0] + TOUCH)
        if body.two_sided:
            add("touch-down -1", lambda t, y: body.gaps(y[0], y[1])[1] + TOUCH)
        if body.f0 > 0.0 and sigma != 0.0:  # the friction's direction turns where v does
            add("halt", lambda t, y: sigma * y[2])
        return events

    def _transition(self, t: float, y: list, contact: float, kind: str) -> tuple[float, list]:
        body = self.body
        omega, omega_dot = self._speed(t)
        if kind == "lift-off":
            s, s1, _, _ = body.flank(y[0], contact)
            return 0.0, [y[0], s, s1 * omega]
        if kind == "halt":
            return 0.0, [y[0], y[1], 0.0]
        flank = 1.0 if kind == "touch-down +1" else -1.0
        return self._struck(t, y, flank, body.land(y[0], omega, omega_dot, y[2], flank))

    def _struck(self, t: float, y: list, flank: float, landed: tuple) -> tuple[float, list]:
        """The state after an impact on ``flank`` (``landed``: SpeedFollower.land's answer), counted."""
        body = self.body
        omega, omega_dot = self._speed(t)
        after, v, _ = landed
        s, s1, _, _ = body.flank(y[0], flank)
        w = v - s1 * omega
        self.impacts.append((t, y[2] - s1 * omega, w))
        if after == 0.0 and w != 0.0:
            # the relative acceleration is at most A near here: the gap stays > 0 for about 2 |w| / A
            self.rebound = abs(w) / (2.0 * body.acceleration_scale(y[0], omega, omega_dot))
        return after, [y[0], s, v]

    def _settle(self, t: float, y: list, contact: float) -> tuple[float, list]:
        """Apply at once a step of omega (the flank's speed jumped, the follower's did not: a lift-off or an impact,
        SpeedFollower.speed_step) and a lift-off whose function is already < 0 (s'' jumped at a breakpoint or the
        input did)."""
        if contact != 0.0:
            omega, omega_dot = self._speed(t)
            after, v, hit = self.body.speed_step(y[0], omega, omega_dot, y[2], contact)
            if hit is not None:
                return self._struck(t, y, contact, (after, v, hit))
            if after == 0.0:   # the flank moves away faster than the follower: it flies on with its speed
                return 0.0, [y[0], self.body.flank(y[0], contact)[0], v]
            if self.body.held(y[0], omega, omega_dot, contact) < 0.0:
                return self._transition(t, y, contact, "lift-off")
            s, s1, _, _ = self.body.flank(y[0], contact)
            return contact, [y[0], s, s1 * omega]
        return contact, y

    def _row(self, t: float, y, contact: float) -> dict[str, float]:
        # at an input's kink or jump its left limit, the interval ending at t (docs/model.md 8.1); at 0 the first piece
        omega = self.omega_ref.left_value(t) if t > 0.0 else self.omega_ref.value(t)
        omega_dot = self.omega_ref.left_slope(t) if t > 0.0 else self.omega_ref.slope(t)
        motion = omega if t == 0.0 else speed_motion(omega, omega_dot, t)   # a stop at t still moves (left limit)
        row = self.body.outputs(float(y[0]), omega, omega_dot, float(y[1]), float(y[2]), contact,
                                1.0 if motion > 0.0 else (-1.0 if motion < 0.0 else 0.0))
        row["impacts"] = float(len(self.impacts))
        return row


def follower_speed_reference(model, grid: np.ndarray, omega_ref: Signal, rtol: float, atol: float) -> dict[str, np.ndarray]:
    """The speed drive with the follower's own state (closures 'form' and 'spring'), on the output grid."""
    return FollowerRun(model, omega_ref, rtol, atol).run(grid, model.params["theta0"])
