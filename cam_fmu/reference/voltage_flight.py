"""The reference of the follower of its own on a voltage-driven cam (docs/model.md section 13.6).

y = (theta, omega, i, s, v), and (phi, omega_m) on a compliant shaft, of ``physics.voltage_follower.VoltageFollower``,
with the energy integrals (hybrid.ENERGY), through the one hybrid loop (hybrid.py) with the events of docs/model.md
13.7: lift-off (the contact force P reaches 0), touch-down (the gap reaches -TOUCH, as flight.py), halt in flight,
the shaft's stop (stuck, or on the other way by the break-away rule with the follower's contact), the stuck shaft's
break-away, the side force's kink and the profile's breakpoints. With the cam stuck the follower flies alone and lands
on it (the impact turns the cam unless on a dwell). Rows are the drive's outputs with the follower's own s, v, a and
N_contact [N], plus contact (+1, -1, 0), impacts (touch-downs so far) and, with energy, the integrals and E_impact
(the impacts' losses so far) [J].
"""
from __future__ import annotations

import math

import numpy as np

from ..physics.drive import sign as sgn
from ..physics.formulations.consistent import SIDE_HYSTERESIS
from ..physics.modes import Event, Follower, Mode, Shaft
from ..physics.signals import Signal
from ..physics.voltage_follower import VoltageFollower
from .flight import FLIGHT_ANGLE, flight_events, flying
from .hybrid import ENERGY, VoltageRun, event, next_breakpoint, piece_input



class VoltageFollowerRun(VoltageRun):
    """One run of the voltage drive with a follower of its own; its mode is ``body.mode``, which the body's
    equations read (the shaft's direction, stuck) and the transitions change in place."""

    label = "voltage follower reference"
    BODY = VoltageFollower  # the follower's equations (physics.kind_follower's for another kind)

    def __init__(self, model, u: Signal, rtol: float, atol: float, energy: bool, method: str | None) -> None:
        super().__init__(model, u, rtol, atol, energy, method)
        self.body = self.BODY(model)
        self.impacts: list[tuple[float, float, float]] = []  # (t [s], w before, w after [m/s])
        self.loss = 0.0  # J, the impacts' losses so far
        self.lift_offs: list[tuple[float, float, float]] = []  # (t [s], s [m], v [m/s]) where the follower left the cam
        self.target = 0.0  # rad, the breakpoint the current piece stops at

    def _mode(self, contact: float, y: list) -> Mode:
        """The body's mode with the follower on the flank ``contact`` (+1, -1), or off the flanks (0)."""
        mode = self.body.mode
        mode.follower = Follower.flank(contact) if contact else flying(self.body, y, 4)
        return mode

    def _extra(self) -> list:
        """The body's states after the shaft's at the start (a train's end mass: TrainFollowerRun); none here."""
        return []

    def _relax(self, y: list, contact: float) -> list:
        """y as the start on the flank ``contact`` (a train's end mass relaxed on it: TrainFollowerRun); y here."""
        return y

    def run(self, grid: np.ndarray) -> dict[str, np.ndarray]:
        body, model = self.body, self.body.model
        p = model.params
        theta0, omega0 = p["theta0"], p["omega0"]
        s_cam, s1, _, _ = body.flank(theta0, 0.0)   # the cam's own lift (no clearance)
        y = [theta0, omega0, p["i0"] if body.has_current else 0.0, s_cam, s1 * omega0]
        y += [0.0, omega0] if body.compliant else []  # the shaft relaxed, the rotor at the cam's speed (model.md 12.1)
        y += self._extra() + [0.0] * len(ENERGY)
        t = float(grid[0])
        body.heading = sgn(omega0)  # from rest: stuck (0) until the break-away rule starts it
        contact, y = self._hold(t, self._relax(y, 1.0), 1.0)
        if contact == 0.0 and body.two_sided:  # a groove: on its other flank if that one holds the follower
            other, y_other = self._hold(t, self._relax(y, -1.0), -1.0)
            if other != 0.0:
                self.lift_offs.pop()
                contact, y = other, y_other
        if body.heading == 0.0:
            contact, y = self._rest(t, y, contact)
        return self.pieces(grid, t, y, self._mode(contact, y),
                           sorted(b for b in self.u.breaks if t < b < float(grid[-1])))

    def _piece(self, t: float, y: list, mode: Mode) -> tuple[list, object, dict]:
        body, n, contact = self.body, self.body.size, mode.contact
        options = {"method": self.method, "atol": [self.atol] * n + [self.atol * 1e-2] * len(ENERGY)}
        if not contact and y[1] != 0.0:  # a flight without a spring is a polynomial: without a bound, one step
            options["max_step"] = FLIGHT_ANGLE / abs(y[1])  # could hold a gap's crossing and its return
        elif not contact and mode.shaft is Shaft.STUCK and body.c > 0.0:  # at a stuck cam: a tenth of the gap
            c, scale = body.c, body.acceleration_scale(y[:n], self.u.value(t))
            options["max_step"] = 0.1 * min(math.sqrt(2.0 * c / scale), c / abs(y[4]) if y[4] else math.inf)
        sigma = body.direction(y[3], y[4]) if mode.follower is Follower.FLIGHT else 0.0  # held over the piece
        u_at = piece_input(self.u, self.piece_end)

        def at(t: float) -> float:   # the piece's input, at its end (an input's break) the left limit
            return u_at(t)[0]
        if mode.shaft is Shaft.STUCK:  # until the torque on the held cam (a current, a shaft) starts it
            events = [event(Event.BREAK_AWAY, lambda t, y: -body.start(y[:n], at(t), contact)[0])]
        else:
            heading = mode.heading
            events = [event(Event.STOP, lambda t, y: heading * y[1])]
        if contact and mode.shaft is not Shaft.STUCK:
            events.append(event(Event.LIFT_OFF, lambda t, y: body.contact_force(y[:n], at(t), contact)))
            side = sgn(body.side_force(y, self.u.value(t), contact)) if body.mu > 0.0 else 0.0
            if side != 0.0:  # the piece ends just past the kink of |N_r| (by 1e-9 N, docs/model.md 10), no transition
                events.append(event(Event.SIDE, lambda t, y: side * body.side_force(y[:n], at(t), contact)
                                    + SIDE_HYSTERESIS))
        elif not contact:
            events += flight_events(body, lambda y: body.gaps(y[0], y[3]), 4, sigma)
        # The piece ends at the profile's next breakpoint, where s'' or the third derivative jumps (docs/model.md
        # 6.3): DOP853 stepping over one with guide friction was 2.5e-7 rad/s off.
        target = self.target = next_breakpoint(self.breakpoints, y[0], 1.0)
        events.append(event(Event.BREAKPOINT, lambda t, y: target - y[0]))
        return events, self._rhs(contact, sigma), options

    def _rhs(self, contact: float, sigma: float):
        body, energy, n = self.body, self.energy, self.body.size
        u_at = piece_input(self.u, self.piece_end)
        R, M_f, d_shaft = body.model.R, body.M_f, body.model.d_shaft

        def rhs(t, y):
            u_t = u_at(t)[0]
            state = y[:n]
            dy = body.rates(state, u_t, contact, sigma)
            if not energy:
                return dy + [0.0] * len(ENERGY)
            i = body.current(state, u_t)
            slip = body.motor_speed(state) - y[1]
            return dy + [u_t * i, R * i * i, M_f * abs(y[1]), body.friction_power(state, u_t, contact, sigma),
                         d_shaft * slip * slip if body.compliant else 0.0]
        return rhs

    # ------------------------------------------------------------- the transitions (docs/model.md 13.7)
    def _at_rest(self, t: float, y: list, mode: Mode, kind: Event) -> tuple[Mode, list]:
        """A stop or a break-away: the rule at rest (``_rest``; at a located break-away it starts at once)."""
        contact, y = self._rest(t, y, mode.contact, kind is Event.BREAK_AWAY)
        return self._mode(contact, y), y

    def _lift_off(self, t: float, y: list, mode: Mode, kind: Event) -> tuple[Mode, list]:
        s, s1, _, _ = self.body.flank(y[0], mode.contact)
        self.lift_offs.append((t, s, s1 * y[1]))
        y = y[:3] + [s, s1 * y[1]] + y[5:]
        return self._mode(0.0, y), y

    def _halt(self, t: float, y: list, mode: Mode, kind: Event) -> tuple[Mode, list]:
        y = y[:4] + [0.0] + y[5:]
        return self._mode(0.0, y), y

    def _side(self, t: float, y: list, mode: Mode, kind: Event) -> tuple[Mode, list]:
        return mode, y

    def _breakpoint(self, t: float, y: list, mode: Mode, kind: Event) -> tuple[Mode, list]:
        # on from just past it: a root a rounding short of it lies on the piece before
        return mode, [max(y[0], self.target + 1e-15 * max(1.0, abs(self.target)))] + y[1:]

    def _touch(self, t: float, y: list, mode: Mode, kind: Event) -> tuple[Mode, list]:
        body, u_t, n = self.body, self.u.value(t), self.body.size
        flank = 1.0 if kind is Event.TOUCH_LOWER else -1.0
        s1 = body.flank(y[0], flank)[1]
        w_before = y[4] - s1 * y[1]
        after, state, hit = body.land(y[:n], u_t, flank)
        self.loss += hit.loss
        self._impact(t, w_before, state[4] - s1 * state[1], after == 0.0, body.acceleration_scale(state, u_t))
        y = state + y[n:]
        return self._mode(after, y), y

    TRANSITIONS = {Event.STOP: _at_rest, Event.BREAK_AWAY: _at_rest, Event.LIFT_OFF: _lift_off, Event.HALT: _halt,
                   Event.SIDE: _side, Event.BREAKPOINT: _breakpoint,
                   Event.TOUCH_LOWER: _touch, Event.TOUCH_UPPER: _touch}

    def _settle(self, t: float, y: list, mode: Mode, after_event: bool) -> tuple[Mode, list]:
        """Before each piece: ``_rest`` while the shaft is stuck (the input may start it), else ``_hold``."""
        if mode.shaft is Shaft.STUCK:
            contact, y = self._rest(t, y, mode.contact)
        else:
            contact, y = self._hold(t, y, mode.contact)
        return self._mode(contact, y), y

    def _rest(self, t: float, y: list, contact: float, at_threshold: bool = False) -> tuple[float, list]:
        """The shaft at rest (the start, an input, a stop, a break-away): stuck with the follower at rest on its flank,
        or moving off toward where the break-away rule sends it (at a located break-away, where its margin is 0 to
        rounding, at once); stuck with the follower off it, the follower flies alone and lands on the cam at rest."""
        body = self.body
        y = [y[0], 0.0, *y[2:]]
        body.heading = 0.0
        contact, y = self._hold(t, y, contact)
        margin, heading = body.start(y[:body.size], self.u.value(t), contact)
        if margin > 0.0 or at_threshold:
            body.heading = heading
            return self._hold(t, y, contact)
        return contact, y

    def _hold(self, t: float, y: list, contact: float) -> tuple[float, list]:
        """On the flank: the follower set on it, or lifted off at once where P is already < 0 (a jump of s'')."""
        if contact:
            s, s1, _, _ = self.body.flank(y[0], contact)
            y = y[:3] + [s, s1 * y[1]] + y[5:]
            if self.body.contact_force(y[:self.body.size], self.u.value(t), contact) < 0.0:
                self.lift_offs.append((t, y[3], y[4]))
                return 0.0, y
        return contact, y

    def _row(self, t: float, y, mode: Mode, left: bool) -> dict[str, float]:
        n = self.body.size
        u = self.u.left_value(t) if t > 0.0 else self.u.value(t)   # at a break its left limit (docs/model.md 8.1)
        row = self.body.outputs([float(x) for x in y[:n]], u, mode.contact)
        row["impacts"] = float(len(self.impacts))
        if self.energy:
            row.update({name: float(value) for name, value in zip(ENERGY, y[n:])}, E_impact=self.loss)
        return row


def follower_voltage_reference(model, grid: np.ndarray, u: Signal, options: dict) -> dict[str, np.ndarray]:
    """The consistent voltage drive with a follower of its own (closures 'spring' and 'form'), on the output grid."""
    run = VoltageFollowerRun(model, u, options["rtol"], options["atol"], options["energy"], options["method"])
    return run.run(grid)
