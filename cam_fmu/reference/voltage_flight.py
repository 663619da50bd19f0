"""The reference of the follower of its own on a voltage-driven cam (docs/model.md section 13.6).

scipy's solve_ivp (DOP853, or Radau with a fast electrical pole) integrates y = (theta, omega, i, s, v) of
``physics.voltage_follower.VoltageFollower``, with the energy integrals E_in = int u i dt, E_copper = int R i^2 dt
and E_shaft = int M_f |omega| dt. Terminal events stop it at each lift-off (the contact force P reaches 0),
touch-down (the gap reaches -TOUCH, as reference/flight.py), the shaft's stop (omega = 0: refused, the
shaft's static friction with a free follower is not modelled) and input break; the transition is applied at the
located time. Rows are the drive's outputs with the follower's own s, v, a and N_contact [N], plus contact (+1, -1, 0),
impacts (touch-downs so far) and, with energy, the integrals and E_impact (the impacts' losses so far) [J].
"""
from __future__ import annotations


import numpy as np

from ..physics.signals import Signal
from ..physics.voltage_follower import VoltageFollower
from .flight import TOUCH, PieceRun

STATE = 5  # theta, omega, i, s, v; then the energy integrals
FLIGHT_ANGLE = 1e-2  # rad: the cam's turn in one integration step at most while the follower flies


class VoltageFollowerRun(PieceRun):
    """One run of the voltage drive with a spring-closed follower of its own."""

    label = "voltage follower reference"

    def __init__(self, model, u: Signal, rtol: float, atol: float, energy: bool, method: str | None) -> None:
        self.body = VoltageFollower(model)
        self.u = u
        self.rtol, self.atol, self.energy = rtol, atol, energy
        stiff = model.L > 0.0 and model.L / model.R < 1e-3
        self.method = method or ("Radau" if stiff else "DOP853")
        self.impacts: list[tuple[float, float, float]] = []  # (t [s], w before, w after [m/s])
        self.loss = 0.0  # J, the impacts' losses so far
        self.lift_offs: list[tuple[float, float, float]] = []  # (t [s], s [m], v [m/s]) where the follower left the cam
        self.rebound = 0.0  # s, shorter than the bounce the last rebound starts (reference/flight.py), or 0

    def run(self, grid: np.ndarray) -> dict[str, np.ndarray]:
        body, model = self.body, self.body.model
        p = model.params
        theta0, omega0 = p["theta0"], p["omega0"]
        s_cam, s1, _, _ = body.program.derivatives(theta0)
        y = [theta0, omega0, p["i0"] if body.has_current else 0.0, s_cam, s1 * omega0] + [0.0, 0.0, 0.0]
        t = float(grid[0])
        contact, y = self._settle(t, y, 1.0)
        if contact == 0.0 and body.two_sided:  # a groove: on its other flank if that one holds the follower
            other, y_other = self._settle(t, y, -1.0)
            if other != 0.0:
                self.lift_offs.pop()
                contact, y = other, y_other
        return self.pieces(grid, t, y, contact, sorted(b for b in self.u.breaks if t < b < float(grid[-1])))

    def _piece(self, t: float, y: list, contact: float) -> tuple[list, object, dict]:
        options = {"method": self.method, "atol": [self.atol] * STATE + [self.atol * 1e-2] * 3}
        if contact == 0.0 and y[1] != 0.0:  # a flight without a spring is a polynomial: without a bound, one step
            options["max_step"] = FLIGHT_ANGLE / abs(y[1])  # could hold a gap's crossing and its return
        return self._events(contact), self._rhs(contact), options

    def _rhs(self, contact: float):
        body, u, energy = self.body, self.u, self.energy
        R, M_f = body.model.R, body.M_f

        def rhs(t, y):
            u_t = u.value(t)
            dy = body.rates(y[:STATE], u_t, contact)
            i = body.current(y[1], y[2], u_t)
            return dy + ([u_t * i, R * i * i, M_f * abs(y[1])] if energy else [0.0, 0.0, 0.0])
        return rhs

    def _events(self, contact: float) -> list:
        body, u = self.body, self.u
        events = []

        def add(kind: str, fn) -> None:
            fn.terminal, fn.direction, fn.kind = True, -1, kind
            events.append(fn)

        add("stop", lambda t, y: y[1])
        if contact:
            add("lift-off", lambda t, y: body.contact_force(y[:STATE], u.value(t), contact))
            return events
        add("touch-down +1", lambda t, y: body.gap(y, 1.0) + TOUCH)
        if body.two_sided:
            add("touch-down -1", lambda t, y: body.gap(y, -1.0) + TOUCH)
        return events

    def _transition(self, t: float, y: list, contact: float, kind: str) -> tuple[float, list]:
        body, u_t = self.body, self.u.value(t)
        if kind == "stop":
            raise RuntimeError(f"{self.label}: the shaft stops at t = {t!r} s; its static friction "
                               "with a follower of its own is not modelled (docs/model.md 13.6)")
        if kind == "lift-off":
            s, s1 = body.flank(y[0], contact)
            self.lift_offs.append((t, s, s1 * y[1]))
            return 0.0, y[:3] + [s, s1 * y[1]] + y[STATE:]
        s1 = body.program.derivatives(y[0])[1]
        w_before = y[4] - s1 * y[1]
        after, state, hit = body.land(y[:STATE], u_t, 1.0 if kind == "touch-down +1" else -1.0)
        self.loss += hit.loss
        w = state[4] - s1 * state[1]
        self.impacts.append((t, w_before, w))
        if after == 0.0 and w != 0.0:
            self.rebound = abs(w) / (2.0 * body.acceleration_scale(state, u_t))
        return after, state + y[STATE:]

    def _settle(self, t: float, y: list, contact: float) -> tuple[float, list]:
        """On the flank: the follower set on it, or lifted off at once where P is already < 0 (a jump of s'')."""
        if contact:
            s, s1 = self.body.flank(y[0], contact)
            y = y[:3] + [s, s1 * y[1]] + y[STATE:]
            if self.body.contact_force(y[:STATE], self.u.value(t), contact) < 0.0:
                self.lift_offs.append((t, y[3], y[4]))
                return 0.0, y
        return contact, y

    def _row(self, t: float, y, contact: float) -> dict[str, float]:
        row = self.body.outputs([float(x) for x in y[:STATE]], self.u.value(t), contact)
        row["impacts"] = float(len(self.impacts))
        if self.energy:
            row.update(E_in=float(y[5]), E_copper=float(y[6]), E_shaft=float(y[7]), E_guide=0.0, E_damp=0.0,
                       E_impact=self.loss)
        return row


def follower_voltage_reference(model, grid: np.ndarray, u: Signal, options: dict) -> dict[str, np.ndarray]:
    """The consistent voltage drive with a follower of its own (closures 'spring' and 'form'), on the output grid."""
    run = VoltageFollowerRun(model, u, options["rtol"], options["atol"], options["energy"], options["method"])
    return run.run(grid)
