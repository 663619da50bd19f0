"""The reference of a follower train on the follower of its own (docs/model.md 14.6), in both drives.

``voltage_flight.VoltageFollowerRun`` with ``physics.train_follower.TrainVoltageFollower``: y = (theta, omega, i, s,
v, [phi, omega_m,] x_e, v_e) and the energy integrals (hybrid.ENERGY; E_damp adds the train damper's d_train (v -
v_e)^2), through the one hybrid loop. The events are the follower of its own's, with two more: on a stuck cam the
flank's force changes through the train alone, so the lift-off is an event there too; a follower halted in flight by
the guide's static friction starts again where the ringing train's pull overcomes it (|net| > f0 + SIDE_HYSTERESIS).
In flight a step turns at most TRAIN_PHASE of the follower's ringing on the train's and the return spring's
stiffness. The end mass starts at rest on the train's spring where its weight holds it, relative to the follower on
its starting flank (x_e = s - contact c + F_ex / k_train, v_e = s' omega0), moved by ``end_offset`` [m] (a test's
let-go). Rows add s_end, v_end, a_end and F_train.

At imposed speed (``TrainSpeedFollowerRun``) the same with ``flight.FollowerRun``: y = (theta, s, v, x_e, v_e), the
end mass's rates beside the follower's on the flank and in flight, its pull in the lift-off's and the flight's forces
(``physics.train_follower.TrainSpeedFollower``), the same TRAIN_PHASE bound in flight. An impact leaves the end mass
as it is (the train's spring is finite).
"""
from __future__ import annotations

import math

import numpy as np

from ..physics.formulations.consistent import SIDE_HYSTERESIS
from ..physics.modes import Event, Follower, Mode, Shaft
from ..physics.signals import Signal
from ..physics.train import Train
from ..physics.train_follower import TrainSpeedFollower, TrainVoltageFollower
from .flight import FollowerRun
from .hybrid import event, piece_input
from .voltage_flight import VoltageFollowerRun

__all__ = ["TrainFollowerRun", "TrainSpeedFollowerRun", "train_follower_reference", "train_speed_follower_reference"]

# rad: the flying follower's phase on sqrt((k_spring + k_train) / m) in one step at most (the engine's bound): a
# gap's crossing and return within one step would go unseen.
TRAIN_PHASE = 0.05


class TrainFollowerRun(VoltageFollowerRun):
    """One run of the voltage drive with a follower of its own carrying the train."""

    label = "train follower reference"
    BODY = TrainVoltageFollower

    def __init__(self, model, u: Signal, rtol: float, atol: float, energy: bool, method: str | None,
                 train: Train | None = None, end_offset: float = 0.0) -> None:
        super().__init__(model, u, rtol, atol, energy, method)
        if train is not None:   # a train given apart from the parameters' (simulate_reference's ``train``)
            self.body = self.BODY(model, train)
        self.end_offset = end_offset
        self.releases: list[float] = []   # s, where a follower halted in flight was started again by the train

    def _extra(self) -> list:
        """The end mass's position and velocity, set on the starting flank by _relax."""
        return [0.0, 0.0]

    def _relax(self, y: list, contact: float) -> list:
        """y with the end mass at rest relative to the follower on the flank ``contact`` (and ``end_offset``)."""
        body = self.body
        s, s1, _, _ = body.flank(y[0], contact)
        x_e, v_e = body.rest(s, s1 * y[1])
        y = list(y)
        y[body.X_E:body.X_E + 2] = [x_e + self.end_offset, v_e]
        return y

    def _mode(self, contact: float, y: list) -> Mode:
        self.body.bind(y)
        return super()._mode(contact, y)

    def _piece(self, t: float, y: list, mode: Mode) -> tuple[list, object, dict]:
        body, n, contact = self.body, self.body.size, mode.contact
        body.bind(y)
        events, rhs, options = super()._piece(t, y, mode)
        u_at = piece_input(self.u, self.piece_end)
        if contact and mode.shaft is Shaft.STUCK:  # the train alone changes the flank's force on a stuck cam
            events.append(event(Event.LIFT_OFF, lambda t, y: body.contact_force(y[:n], u_at(t)[0], contact)))
        if not contact:
            flight_bound(body, options)
            body.bind(y)
            if mode.follower is Follower.HALTED and body.f0 > 0.0:  # held by the guide until the train's pull beats it

                def release(t, y):
                    body.bind(y)
                    return body.f0 + SIDE_HYSTERESIS - abs(body.net_at_rest(y[3]))
                events.append(event(Event.HALT, release))
        return events, rhs, options

    def _halt(self, t: float, y: list, mode: Mode, kind: Event) -> tuple[Mode, list]:
        if mode.follower is Follower.HALTED:   # the release: the train's pull beat the guide's static friction
            self.releases.append(t)
        return super()._halt(t, y, mode, kind)

    TRANSITIONS = {**VoltageFollowerRun.TRANSITIONS, Event.HALT: _halt}

    def _rhs(self, contact: float, sigma: float):
        body, n = self.body, self.body.size
        rhs = super()._rhs(contact, sigma)
        if not self.energy or body.train.d_train == 0.0:
            return rhs

        def with_damper(t, y):
            dy = rhs(t, y)
            dy[-1] += body.train_damping(y[:n], contact)
            return dy
        return with_damper


def train_follower_reference(model, grid: np.ndarray, u: Signal, options: dict, train: Train | None = None,
                             end_offset: float = 0.0, runner: type | None = None) -> dict[str, np.ndarray]:
    """The consistent voltage drive with a follower of its own (closures 'spring', 'form' with c > 0) carrying
    ``train`` (None: the parameters' k_train, d_train, m_end), on the output grid; ``end_offset`` [m] moves the end
    mass from its rest at the start. ``runner``: the run's class (TrainFollowerRun; another kind's, kind_flight)."""
    run = (runner or TrainFollowerRun)(model, u, options["rtol"], options["atol"], options["energy"],
                                       options["method"], train, end_offset)
    return run.run(grid)


def flight_bound(body, options: dict) -> None:
    """Bound a flying step to TRAIN_PHASE of the follower's ringing on the return spring and the train."""
    rate = math.sqrt(body.flight_stiffness() / body.m)
    options["max_step"] = min(options.get("max_step", math.inf), TRAIN_PHASE / rate)


def _bound_event(body, fn):
    """The event function ``fn`` (t, y) seeing the end mass of the state it is given (``body.bind`` first)."""
    def value(t, y):
        body.bind(y)
        return fn(t, y)
    return event(fn.kind, value)


def _bound_transition(fn):
    """The transition ``fn`` deciding (held, land) with the end mass of the state it is given."""
    def transition(run, t, y, mode, kind):
        run.body.bind(y)
        return fn(run, t, y, mode, kind)
    return transition


class TrainSpeedFollowerRun(FollowerRun):
    """One run of the speed drive with a follower of its own carrying the train: y = (theta, s, v, x_e, v_e)."""

    label = "train speed follower reference"
    BODY = TrainSpeedFollower

    def _holds(self, theta: float, omega: float, omega_dot: float, side: float) -> float:
        """N, > 0 where the flank ``side`` holds the follower at the start, the end mass at rest relative to it."""
        s, s1, _, _ = self.body.flank(theta, side)
        self.body.bind([theta, s, s1 * omega, *self.body.rest(s, s1 * omega)])
        return self.body.held(theta, omega, omega_dot, side)

    def _start(self, y: list, omega: float) -> list:
        """y with the end mass at rest relative to the follower at its start (the train's weight on its spring)."""
        return [*y, *self.body.rest(y[1], y[2])]

    def _piece(self, t: float, y: list, mode: Mode) -> tuple[list, object, dict]:
        body, speed, contact = self.body, piece_input(self.omega_ref, self.piece_end), mode.contact
        body.bind(y)
        events, rhs, options = super()._piece(t, y, mode)
        bound = [_bound_event(body, fn) for fn in events]

        def with_end(t, y):
            body.bind(y)
            return rhs(t, y) + body.end_rates(body.train_force(y, speed(t)[0], contact), y)
        if not contact:
            flight_bound(body, options)
            if mode.follower is Follower.HALTED and body.f0 > 0.0:  # held by the guide until the train's pull beats it
                release = event(Event.HALT, lambda t, y: body.f0 + SIDE_HYSTERESIS - abs(body.net_at_rest(y[1])))
                bound.append(_bound_event(body, release))
        return bound, with_end, options

    def _settle(self, t: float, y: list, mode: Mode, after_event: bool) -> tuple[Mode, list]:
        self.body.bind(y)
        return super()._settle(t, y, mode, after_event)

    TRANSITIONS = {kind: _bound_transition(fn) for kind, fn in FollowerRun.TRANSITIONS.items()}

    def _row(self, t: float, y, mode: Mode, left: bool) -> dict[str, float]:
        self.body.bind(y)
        row = super()._row(t, y, mode, left)
        omega = self.omega_ref.left_value(t) if t > 0.0 else self.omega_ref.value(t)
        row.update(self.body.end_outputs(y, self.body.train_force(y, omega, mode.contact)))
        return row


def train_speed_follower_reference(model, grid: np.ndarray, omega_ref: Signal, options: dict,
                                   train: Train | None = None, runner: type | None = None) -> dict[str, np.ndarray]:
    """The speed drive with a follower of its own (closures 'spring', 'form' with c > 0) carrying ``train`` (None:
    the parameters'), on the output grid [s]. ``runner``: the run's class (TrainSpeedFollowerRun; another kind's)."""
    run = (runner or TrainSpeedFollowerRun)(model, omega_ref, options["rtol"], options["atol"])
    if train is not None:
        run.body = run.BODY(model, train)
    return run.run(grid, model.params["theta0"])
