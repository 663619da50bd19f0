"""The voltage drive with the follower train (docs/model.md 14.6): the cam, the motor and the end mass integrated
together by scipy, with the shaft's and the guide's Coulomb friction.

y = (theta, omega, i, x_e, v_e, W_train, E_train_damp, E_in, E_copper, E_shaft, E_guide): the rigid drive's
equation (5.1) with the train's force F_train on the follower (``DriveModel.omega_dot``'s ``axial``: it enters the
axial force, so the guide's side force N_r and its friction f; a translating flat's KindDriveModel takes it into its P,
whose sign is then the side event and mu |P| (r_b + s) the friction, E_guide its loss), i a state with L > 0 (held,
and quasi-static, with L = 0), the end mass's two states and six energy integrals: W_train = int F_train v dt,
E_train_damp = int d_train (v - v_e)^2 dt, E_in = int u i dt, E_copper = int R i^2 dt, E_shaft = int M_f |omega| dt,
E_guide = int f |v| dt. The run is reference/hybrid.py's loop with the consistent drive's modes (physics/formulations/
consistent.py, section 10): turning one way (friction against it, the guide's friction on the branch of N_r's
sign) or stuck (omega = 0 while the torque on the held cam, F_train's included, stays within static friction: the
end mass rings on and the current runs). Events: the stop (omega reaches 0: stuck, or on the other way by the
break-away rule), the break-away (the stuck shaft's torque, which the ringing train changes, overcomes static
friction), the side force's sign, and the profile's breakpoints (s'', s''' jump there). DOP853, or Radau with a
fast electrical pole, as the rigid reference.

A compliant shaft (k_shaft > 0, docs/model.md section 12) adds y's states twist = theta_m - theta [rad] and the
rotor's omega_m [rad/s] after the end mass's (TWIST, OMEGA_M) and E_damp = int d_shaft (omega_m - omega)^2 dt
after the integrals: the cam side (J_cam + m s'^2) takes the shaft's torque M_shaft = k_shaft twist + d_shaft
(omega_m - omega) in place of the motor's, the rotor J_m omega_m' = c_m i - M_shaft, the current sees omega_m; the
held cam's break-away margin uses M_shaft (omega = 0), as reference/integrate.py's compliant drive. A clearance and
a follower of its own are refused here with that reason (a follower of its own carries the train in
reference/train_flight.py, where simulate_reference routes it).
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..physics.drive import DriveModel
from ..physics.formulations.consistent import SIDE_HYSTERESIS
from ..physics.modes import Event
from ..physics.parameters import ParameterError
from ..physics.signals import Signal
from ..physics.train import Train, end_weight
from ..physics.variables import output_record
from .hybrid import VoltageRun, event, next_breakpoint, piece_input

__all__ = ["voltage_train_reference", "TRAIN_ENERGY", "SHAFT_ENERGY"]

THETA, OMEGA, CURRENT, X_E, V_E, TWIST, OMEGA_M = range(7)  # TWIST, OMEGA_M: a compliant shaft's
# rad/s: the stop fires where omega has passed 0 by this much. A shaft started at a located break-away (its
# acceleration 0 to rounding there, then growing) may dip a rounding the wrong way first: a stop at 0 itself fired
# there at once and the run stalled between the two events (L > 0, at a voltage step to 0). The kinetic energy the
# stop then drops, J (1e-12)^2 / 2, is nothing.
STOP_SLACK = 1e-12
# J: the energy integrals after the five states (seven with a compliant shaft), in this order.
TRAIN_ENERGY = ("W_train", "E_train_damp", "E_in", "E_copper", "E_shaft", "E_guide")
# J: a compliant shaft's damper loss int d_shaft (omega_m - omega)^2 dt, after TRAIN_ENERGY (the name
# reference/integrate.py's compliant drive gives it).
SHAFT_ENERGY = ("E_damp",)


def _check(model: DriveModel) -> None:
    refused = [name for name, on in (("'c' (clearance)", model.c != 0.0),
                                     ("'closure' (a follower of its own)", model.free_follower)) if on]
    if refused:
        raise ParameterError(f"the follower train in the voltage drive runs without clearance or follower of its "
                             f"own so far: parameters {', '.join(refused)} must be off "
                             f"(their events do not carry the train yet)")


@dataclass
class _Mode:
    """Stuck, or turning toward ``direction``; ``side``: the sign of the guide's side force N_r (the friction's
    branch) while turning."""

    stuck: bool
    direction: float
    side: float = 1.0


class _VoltageTrain(VoltageRun):
    label = "train reference"

    def __init__(self, model: DriveModel, u: Signal, train: Train, rtol: float, atol: float,
                 method: str | None) -> None:
        super().__init__(model, u, rtol, atol, True, method)
        self.model, self.train = model, train
        self.F_ex = end_weight(train, model.params)
        self.guide = model.mu > 0.0  # the side force's sign is an event
        self.target = math.nan       # rad, the breakpoint ahead of the piece
        self.compliant = model.compliant
        self.n = 7 if self.compliant else 5  # continuous states before the energy integrals
        self.energy_names = TRAIN_ENERGY + (SHAFT_ENERGY if self.compliant else ())

    def run(self, grid: np.ndarray) -> dict[str, np.ndarray]:
        p, k = self.model.params, self.train.k_train
        theta0, omega0 = p["theta0"], p["omega0"]
        s0, s1_0 = self.model.program.derivatives(theta0)[:2]
        y = [theta0, omega0, p["i0"] if self.model.L > 0.0 else 0.0, s0 + self.F_ex / k, s1_0 * omega0]
        if self.compliant:  # the shaft relaxed, the rotor at the cam's speed (docs/model.md 12.1)
            y += [0.0, omega0]
        mode = _Mode(stuck=omega0 == 0.0, direction=1.0 if omega0 >= 0.0 else -1.0)
        return self.pieces(grid, 0.0, y + [0.0] * len(self.energy_names), mode,
                           [b for b in self.u.breaks if 0.0 < b < float(grid[-1])])

    # ------------------------------------------------------------ the drive at one instant
    def _motor_speed(self, y) -> float:
        """The rotor's speed [rad/s]: the cam's, or omega_m beyond a compliant shaft."""
        return y[OMEGA_M] if self.compliant else y[OMEGA]

    def _current(self, y, u_t: float) -> float:
        return y[CURRENT] if self.model.L > 0.0 else self.model.motor.quasi_static_current(u_t, self._motor_speed(y))

    def _torque(self, y, u_t: float, omega: float) -> float:
        """The torque that drives the cam [N m] with the cam at omega [rad/s]: the motor's c_m i, or the compliant
        shaft's M_shaft = k_shaft twist + d_shaft (omega_m - omega)."""
        model = self.model
        if self.compliant:
            return model.k_shaft * y[TWIST] + model.d_shaft * (y[OMEGA_M] - omega)
        return model.c_m * self._current(y, u_t)

    def _force(self, y, omega: float) -> tuple[float, float]:
        """(F_train [N], the follower's v [m/s]) at y with the cam at omega [rad/s]."""
        s, s1 = self.model.program.derivatives(y[THETA])[:2]
        v = s1 * omega
        return self.train.force(s, v, y[X_E], y[V_E]), v

    def _omega_dot(self, y, u_t: float, direction: float, side: float, omega: float) -> float:
        F, _ = self._force(y, omega)
        return self.model.omega_dot(y[THETA], omega, self._torque(y, u_t, omega), direction, True, side, F)

    def _side_force(self, y, u_t: float, mode: _Mode, side: float) -> float:
        """N_r [N] on the branch ``side`` (0: the one that holds), the train's force in the axial force."""
        omega = y[OMEGA]
        F, _ = self._force(y, omega)
        return self.model.side_force(y[THETA], omega, self._torque(y, u_t, omega), mode.direction, side, F)

    def _margin(self, y, u_t: float) -> float:
        """> 0 when the held shaft would start [rad/s2]: the larger acceleration either way, friction against it."""
        return max(self._omega_dot(y, u_t, 1.0, 0.0, 0.0), -self._omega_dot(y, u_t, -1.0, 0.0, 0.0))

    def _rates(self, y, u_t: float, mode: _Mode) -> list[float]:
        model, train = self.model, self.train
        omega = 0.0 if mode.stuck else y[OMEGA]
        i = self._current(y, u_t)
        F, v = self._force(y, omega)
        slip = v - y[V_E]
        di = model.motor.current_rate(u_t, i, self._motor_speed(y)) if model.L > 0.0 else 0.0
        rates = [0.0, 0.0, di, y[V_E], (F + self.F_ex) / train.m_end]
        torque = self._torque(y, u_t, omega)
        if self.compliant:  # the twist's rate and the rotor under the motor's torque less the shaft's
            rates += [y[OMEGA_M] - omega, (model.c_m * i - torque) / model.J_m]
        rates += [F * v, train.d_train * slip * slip, u_t * i, model.R * i * i, 0.0, 0.0]
        if self.compliant:
            shaft_slip = y[OMEGA_M] - omega
            rates.append(model.d_shaft * shaft_slip * shaft_slip)
        e_shaft, e_guide = self.n + 4, self.n + 5  # slots of E_shaft, E_guide
        if not mode.stuck:
            side = mode.side if self.guide else 0.0
            rates[THETA] = omega
            rates[OMEGA] = model.omega_dot(y[THETA], omega, torque, mode.direction, True, side, F)
            # The friction's power as the mode applies it, M_f d omega and sigma f v (= M_f |omega|, f |v| while
            # d = sgn(omega)): smooth up to the stop that ends the piece, where |omega| would put a kink inside the
            # integrator's last step and its interpolant at the stop (measured: 7.5e-10 J off the balance).
            rates[e_shaft] = model.M_f * mode.direction * omega
            if self.guide:
                drive = torque - model.M_f * mode.direction
                rates[e_guide] = model.follower_friction_power(y[THETA], omega, drive, mode.direction, side, F)
        return rates

    # ------------------------------------------------------------ the hybrid run's parts
    def _piece(self, t: float, y: list, mode: _Mode):
        u_at = piece_input(self.u, self.piece_end)

        def rhs(t, y):
            return self._rates(y, u_at(t)[0], mode)

        if mode.stuck:
            return [event(Event.BREAK_AWAY, lambda t, y: -self._margin(y, u_at(t)[0]))], rhs, {"method": self.method,
                                                                                               "atol": self.atol}
        direction = mode.direction
        target = next_breakpoint(self.breakpoints, y[THETA], direction)
        self.target = target
        events = [event(Event.STOP, lambda t, y: direction * y[OMEGA] + STOP_SLACK),
                  event(Event.BREAKPOINT, lambda t, y: direction * (target - y[THETA]))]
        if self.guide:
            events.append(event(Event.SIDE, lambda t, y: self._side_value(y, u_at(t)[0], mode)))
        return events, rhs, {"method": self.method, "atol": self.atol}

    def _side_value(self, y, u_t: float, mode: _Mode) -> float:
        """> 0 while the guide's friction branch ``mode.side`` holds."""
        return mode.side * self._side_force(y, u_t, mode, mode.side) + SIDE_HYSTERESIS

    def _rows_first(self, t: float, after_event: bool) -> bool:
        # At an input's break the outputs due there are its left limit (as the rigid reference's, model.md 8.1).
        return not after_event and t > 0.0 and t in self.u.breaks

    def _settle(self, t: float, y: list, mode: _Mode, after_event: bool):
        """At the start and at an input's break the break-away rule (the torque may have jumped with u); then the
        friction branch, whose side force may have jumped (at a breakpoint s'' does)."""
        u_t = self.u.value(t)
        if not after_event:
            self._start(y, u_t, mode, False)
        if self.guide and not mode.stuck and self._side_value(y, u_t, mode) < 0.0:
            mode.side = -mode.side
        return mode, y

    def _start(self, y: list, u_t: float, mode: _Mode, at_threshold: bool) -> None:
        """At rest (omega = 0): stay stuck, or turn the way the torque beats static friction (at a located
        break-away, toward the larger acceleration); then the friction branch."""
        if not mode.stuck:
            if y[OMEGA] != 0.0 or mode.direction * self._omega_dot(y, u_t, mode.direction, 0.0, 0.0) >= 0.0:
                return
            mode.stuck = True
        forward = self._omega_dot(y, u_t, 1.0, 0.0, 0.0)
        backward = -self._omega_dot(y, u_t, -1.0, 0.0, 0.0)
        if forward > 0.0 or backward > 0.0 or at_threshold:  # a located break-away: its margin is 0 to rounding
            direction = 1.0 if forward >= backward else -1.0
            if forward == backward and self.compliant:
                # A tie (no friction, no torque on the cam as the twist passes through 0): the cam goes where the
                # shaft's torque is heading, as the compliant reference's rule (physics/formulations/consistent.py).
                heading = self._heading(y, u_t)
                direction = direction if heading == 0.0 else (1.0 if heading > 0.0 else -1.0)
            mode.stuck, mode.direction = False, direction
            y[OMEGA] = 0.0
            n_r = self._side_force(y, u_t, mode, 0.0) if self.guide else 0.0
            if abs(n_r) > SIDE_HYSTERESIS:
                mode.side = 1.0 if n_r > 0.0 else -1.0

    def _heading(self, y, u_t: float) -> float:
        """Where a compliant shaft's torque on the held cam is heading: the sign of omega_m (the twist's rate), else
        of the rotor's acceleration, else of the current's rate."""
        model = self.model
        rate = y[OMEGA_M]
        if rate == 0.0:
            rate = model.c_m * self._current(y, u_t) - self._torque(y, u_t, 0.0)
        if rate == 0.0 and model.L > 0.0:
            rate = model.motor.current_rate(u_t, y[CURRENT], 0.0)
        return rate

    def _stop(self, t: float, y: list, mode: _Mode, kind: Event):
        y[OMEGA] = 0.0
        mode.stuck = True
        self._start(y, self.u.value(t), mode, False)
        return mode, y

    def _break_away(self, t: float, y: list, mode: _Mode, kind: Event):
        self._start(y, self.u.value(t), mode, True)
        return mode, y

    def _flip_side(self, t: float, y: list, mode: _Mode, kind: Event):
        mode.side = -mode.side  # N_r passed through zero: the other friction branch
        return mode, y

    def _breakpoint(self, t: float, y: list, mode: _Mode, kind: Event):
        # on from just past it, as the rigid reference (s'' and s''' of the piece ahead)
        y[THETA] = self.target + mode.direction * 1e-15 * max(1.0, abs(self.target))
        return mode, y

    TRANSITIONS = {Event.STOP: _stop, Event.BREAK_AWAY: _break_away, Event.SIDE: _flip_side,
                   Event.BREAKPOINT: _breakpoint}

    def _row(self, t: float, y, mode: _Mode, left: bool) -> dict[str, float]:
        model, train = self.model, self.train
        u_t = self.u.left_value(t) if left else self.u.value(t)
        theta = float(y[THETA])
        omega = 0.0 if mode.stuck else float(y[OMEGA])
        i = self._current(y, u_t)
        F, _ = self._force(y, omega)
        torque = self._torque(y, u_t, omega)
        if mode.stuck:
            load = model.load(theta, 0.0, 0.0, 0.0, True, F)
            load.M = torque  # static friction takes whatever the motor (or the shaft) applies
            load.v = load.a = 0.0
        else:
            side = mode.side if self.guide else 0.0
            omega_dot = model.omega_dot(theta, omega, torque, mode.direction, True, side, F)
            load = model.load(theta, omega, omega_dot, mode.direction, True, F)
        rotor = dict(theta_m=theta, omega_m=omega, M_shaft=0.0)  # rigid: the rotor turns with the cam
        J = load.J
        if self.compliant:  # J counts the rotor too, as the compliant reference's does
            J = load.J + model.J_m
            rotor = dict(theta_m=theta + float(y[TWIST]), omega_m=float(y[OMEGA_M]), M_shaft=torque)
        row = output_record(omega=omega, theta=theta, s=load.s_cam, i=i, M=load.M, J=J, v=load.v, a=load.a,
                            alpha=load.alpha, s_cam=load.s_cam, voltage=u_t, N_contact=load.N, **rotor)
        return row | {"s_end": float(y[X_E]), "v_end": float(y[V_E]), "a_end": (F + self.F_ex) / train.m_end,
                      "F_train": F} | {name: float(value) for name, value in zip(self.energy_names, y[self.n:])}


def voltage_train_reference(model: DriveModel, grid: np.ndarray, u: Signal, train: Train, rtol: float,
                            atol: float, method: str | None) -> dict[str, np.ndarray]:
    """The voltage drive with ``train`` on ``grid`` [s]: the drive's outputs with F_train in the load (and in the
    guide's friction), the train's outputs and integrals (reference.train_speed.TRAIN_INTEGRALS) and E_in, E_copper, E_shaft,
    E_guide [J]."""
    _check(model)
    return _VoltageTrain(model, u, train, rtol, atol, method).run(grid)
