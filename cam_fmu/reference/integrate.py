"""Direct-Python reference integration of the drive with scipy (the ground truth).

It integrates the same hybrid system as the FMU (physics.formulations.consistent) with
scipy.integrate.solve_ivp at tight tolerances, and stops at every non-smooth
point instead of stepping over it: profile segment ends (s''' jumps), input
breaks, stick/slip and backlash contact changes; each transition is applied at
the located time and the integration restarts there. L > 0 with a fast
electrical pole uses Radau (implicit), otherwise DOP853.

Results are a dict of numpy arrays on the output grid: time and the outputs of
physics.variables.OUTPUTS. With ``energy=True`` four integrals are added [J]:
E_in = int u i dt, E_copper = int R i^2 dt, E_shaft = int M_f |omega| dt,
E_guide = int f |v| dt and E_damp = int d_shaft (omega_m - omega)^2 dt (a compliant
shaft's damping), for the power balance.
"""
from __future__ import annotations

import math
from typing import Any, Mapping

import numpy as np
from scipy.integrate import solve_ivp

from ..physics.signals import Signal, constant
from ..physics.contact import follower_along, rest_position, speed_engaged
from ..physics.drive import DriveModel, sign
from ..physics.formulations import formulation_name
from ..physics.formulations.consistent import HybridDrive
from ..physics.formulations.paper import PaperScheme, calculation_steps
from ..physics.formulations.speed import speed_drive_outputs
from ..physics.variables import INPUT_STARTS, OUTPUTS
from .flight import follower_speed_reference, next_breakpoint, piece_input, speed_motion
from .voltage_flight import follower_voltage_reference

ENERGY = ("E_in", "E_copper", "E_shaft", "E_guide", "E_damp")


def simulate_reference(
    params: Mapping[str, Any] | None,
    stop_time: float,
    output_interval: float,
    u: Signal | None = None,
    omega_ref: Signal | None = None,
    rtol: float = 1e-12,
    atol: float = 1e-13,
    energy: bool = False,
    method: str | None = None,
) -> dict[str, np.ndarray]:
    """Run the drive from 0 to ``stop_time`` [s]; outputs every ``output_interval`` [s]."""
    model = DriveModel(params)
    u = u or constant(INPUT_STARTS["u"])
    omega_ref = omega_ref or constant(INPUT_STARTS["omega_ref"])
    grid = _grid(stop_time, output_interval)
    options = {"rtol": rtol, "atol": atol, "energy": energy, "method": method}
    return REFERENCES[formulation_name(model)](model, grid, u, omega_ref, options)


def _grid(stop_time: float, output_interval: float) -> np.ndarray:
    if not (stop_time > 0.0 and output_interval > 0.0):
        raise ValueError(f"stop_time = {stop_time} s and output_interval = {output_interval} s must be > 0")
    n = int(math.floor(stop_time / output_interval * (1.0 + 1e-12)))
    grid = np.arange(n + 1) * output_interval
    if stop_time - grid[-1] > 1e-9 * stop_time:  # a last, shorter interval ends at stop_time, as fmpy does
        grid = np.append(grid, stop_time)
    return grid


def _collect(rows: list[dict[str, float]], grid: np.ndarray) -> dict[str, np.ndarray]:
    result = {"time": grid.copy()}
    for name in rows[0]:
        result[name] = np.array([row[name] for row in rows])
    return result


class _Consistent:
    def __init__(self, model: DriveModel, u: Signal, rtol: float, atol: float, energy: bool, method: str | None) -> None:
        self.model = model
        self.hybrid = HybridDrive(model)
        self.u = u
        self.rtol, self.atol = rtol, atol
        self.energy = energy
        stiff = model.L > 0.0 and model.L / model.R < 1e-3
        self.method = method or ("Radau" if stiff else "DOP853")
        two_pi = 2.0 * math.pi
        self.breakpoints = sorted(set(model.program.breakpoints()) | {0.0}) + [two_pi]

    def _next_breakpoint(self, theta: float, direction: float) -> float:
        """The first profile breakpoint strictly ahead of theta in the direction of motion [rad]."""
        return next_breakpoint(self.breakpoints, theta, direction)

    def run(self, grid: np.ndarray) -> dict[str, np.ndarray]:
        model, hybrid, u = self.model, self.hybrid, self.u
        p = model.params
        y, mode = hybrid.initial(p["theta0"], p["omega0"], p["i0"])
        y = list(y) + ([0.0] * len(ENERGY) if self.energy else [])
        n = hybrid.size
        t, stop = 0.0, float(grid[-1])
        rows: list[dict[str, float]] = []
        k_out = 0
        breaks = [b for b in u.breaks if 0.0 < b < stop] + [stop]
        events_seen = 0
        stalled, t_event_last = 0, -math.inf  # events at one instant in a row
        input_changed = True  # at the start and at each input break: decide stick/slip anew
        while True:
            u_now = u.value(t)
            if input_changed and t in u.breaks and t > 0.0:
                # Outputs due at an input's break: its left limit, the mode and the input before it (docs/model.md
                # 8.1), as a co-simulation step that ends there.
                while k_out < len(grid) and grid[k_out] <= t + 1e-12:
                    rows.append(hybrid.outputs(y[:n], u.left_value(t), mode) | self._energy_row(y))
                    k_out += 1
            if input_changed:
                # Not after an event: its transition has settled the mode already, and
                # settling again at a located break-away (margin ~ -1e-17) re-sticks it.
                hybrid.settle(y, u_now, mode)
            # Outputs due at t (after any transition at t).
            while k_out < len(grid) and grid[k_out] <= t + 1e-12:
                rows.append(hybrid.outputs(y[:n], u.value(float(grid[k_out])), mode) | self._energy_row(y))
                k_out += 1
            if t >= stop - 1e-12:
                break
            t_end = next(b for b in breaks if b > t + 1e-12)
            self.piece_end = t_end   # the piece's input up to t_end is its own (flight.piece_input)
            # theta is integrated relative to the last whole turn: rtol then acts on
            # an angle below 4 pi, not on the unbounded theta (long runs keep their accuracy).
            base = 2.0 * math.pi * math.floor(y[0] / (2.0 * math.pi))
            names = list(hybrid.event_names(mode))
            due = self._due(y[:n], u_now, mode, names)
            if due is not None:
                # An event function below zero at the start: it jumped there, which solve_ivp's crossing
                # search cannot see. The side force N_r does at a breakpoint where s'' jumps (every row of a
                # motion table): its transition applies now, as the C engine's at a step's start.
                stalled = stalled + 1 if t <= t_event_last else 0
                t_event_last = t
                if stalled > 1000:
                    raise RuntimeError(f"reference integration: more than 1000 events at t = {t!r} s "
                                       f"without progress (last mode {mode})")
                events_seen += 1
                hybrid.apply_event(y, u_now, mode, due)
                input_changed = False
                continue
            funcs = [self._event(k, mode, base) for k in range(len(names))]
            if not mode.stuck:
                target = self._next_breakpoint(y[0], mode.direction)
                funcs.append(self._breakpoint_event(target - base, mode.direction))
                names.append("breakpoint")
            for fn in funcs:
                fn.terminal, fn.direction = True, -1
            # A rejected trial step of an explicit method can overflow (u = 100 V):
            # the error control discards it; numpy's warning about it is noise.
            with np.errstate(over="ignore", invalid="ignore"):
                sol = solve_ivp(
                    self._rhs(mode, base), (t, t_end), [y[0] - base, *y[1:]], method=self.method, rtol=self.rtol,
                    atol=self._atol(len(y)), events=funcs or None, dense_output=True,
                )
            if sol.status < 0:
                raise RuntimeError(f"reference integration failed at t = {t}: {sol.message}")
            t_stop = float(sol.t[-1])
            while k_out < len(grid) and grid[k_out] < t_stop - 1e-12 * max(1.0, t_stop):
                tk = float(grid[k_out])
                yk = list(sol.sol(tk))
                yk[0] += base
                rows.append(hybrid.outputs(yk[:n], u.value(tk), mode) | self._energy_row(yk))
                k_out += 1
            y = list(sol.y[:, -1])
            y[0] += base
            t = t_stop
            input_changed = sol.status != 1
            if sol.status == 1:
                stalled = stalled + 1 if t_stop <= t_event_last else 0
                t_event_last = t_stop
                if stalled > 1000:  # events at one instant without end (Zeno): never a hang
                    raise RuntimeError(f"reference integration: more than 1000 events at t = {t_stop!r} s "
                                       f"without progress (last mode {mode})")
                fired = [k for k, te in enumerate(sol.t_events) if len(te)]
                k = min(fired, key=lambda j: sol.t_events[j][0])
                y = list(sol.y_events[k][0])
                y[0] += base
                events_seen += 1
                if not mode.stuck and abs(target - y[0]) <= 1e-12 * max(1.0, abs(target)):
                    # At the breakpoint: go on from just past it, as the C engine ends its step there. A root
                    # located a rounding short of it lies where s'' is still the piece's before (the left
                    # limit), and an event caused by the jump there (N_r's sign at a motion table's row)
                    # would be applied on the wrong side of its cause.
                    past = target + mode.direction * 1e-15 * max(1.0, abs(target))
                    if mode.direction * (past - y[0]) > 0.0:
                        y[0] = past
                if names[k] != "breakpoint":
                    hybrid.apply_event(y, u.value(t), mode, names[k])
        self.events_seen = events_seen
        return _collect(rows, grid)

    def _due(self, y, u: float, mode, names: list[str]) -> str | None:
        """The first event whose function is already below zero at the state y (it jumped there), or None."""
        for name, value in zip(names, self.hybrid.event_values(y, u, mode)):
            if value < 0.0:
                return name
        return None

    def _atol(self, size: int) -> list[float]:
        tol = [self.atol] * size
        if self.energy:
            tol[-len(ENERGY):] = [self.atol * 1e-2] * len(ENERGY)
        return tol

    def _rhs(self, mode, base: float):
        hybrid, model, n = self.hybrid, self.model, self.hybrid.size
        energy, u_at = self.energy, piece_input(self.u, self.piece_end)

        def rhs(t, y):
            u_t = u_at(t)[0]
            state = [y[0] + base, *y[1:n]]
            dy = list(hybrid.derivative(state, u_t, mode))
            if energy:
                i = hybrid.current(state, u_t)
                omega = 0.0 if mode.stuck else y[1]
                load = model.load(state[0], omega, dy[1], mode.direction, mode.contact != 0)
                slip = hybrid.motor_speed(state) - omega
                dy += [u_t * i, model.R * i * i, model.M_f * abs(omega), load.f * abs(load.v),
                       model.d_shaft * slip * slip]
            return dy

        return rhs

    def _event(self, k: int, mode, base: float):
        hybrid, n, u_at = self.hybrid, self.hybrid.size, piece_input(self.u, self.piece_end)
        return lambda t, y: hybrid.event_values([y[0] + base, *y[1:n]], u_at(t)[0], mode)[k]

    @staticmethod
    def _breakpoint_event(target: float, direction: float):
        return lambda t, y: direction * (target - y[0])

    def _energy_row(self, y) -> dict[str, float]:
        if not self.energy:
            return {}
        return dict(zip(ENERGY, y[-len(ENERGY):]))


def _consistent(model: DriveModel, grid: np.ndarray, u: Signal, omega_ref: Signal, options: dict) -> dict[str, np.ndarray]:
    """The consistent formulation: scipy at tight tolerances, stopping at every event and breakpoint."""
    if model.free_follower:  # its own state (model.md 13.6)
        return follower_voltage_reference(model, grid, u, options)
    return _Consistent(model, u, options["rtol"], options["atol"], options["energy"], options["method"]).run(grid)


def _paper(model: DriveModel, grid: np.ndarray, u: Signal, omega_ref: Signal, options: dict) -> dict[str, np.ndarray]:
    """The paper's algorithm on its fixed grid of calculation steps T = h_max (it is its own reference)."""
    p = model.params
    scheme = PaperScheme(model, p["theta0"], p["omega0"], p["i0"])
    scheme.voltage = u.value(0.0)
    rows = [scheme.outputs()]
    for t0, t1 in zip(grid[:-1], grid[1:]):
        h = float(t1 - t0)
        steps = calculation_steps(h, p["h_max"])
        for j in range(steps):
            scheme.step(h / steps, u.value(float(t0) + j * h / steps), int(p["max_steps"]))
        rows.append(scheme.outputs())
    return _collect(rows, grid)


def _speed(model: DriveModel, grid: np.ndarray, u: Signal, omega_ref: Signal, options: dict) -> dict[str, np.ndarray]:
    """Imposed speed: theta = theta0 + int omega_ref dt (exact for piecewise-linear signals)."""
    p = model.params
    if model.free_follower:  # the follower's own state
        return follower_speed_reference(model, grid, omega_ref, options["rtol"], options["atol"])
    theta = p["theta0"]
    s = model.program.derivatives(theta)[0]

    def integral(t0: float, t1: float) -> float:
        pts = [t0] + [b for b in omega_ref.breaks if t0 < b < t1] + [t1]
        return sum(0.5 * (omega_ref.value(a) + omega_ref.value(b - 1e-15 * max(1.0, b))) * (b - a)
                   for a, b in zip(pts[:-1], pts[1:]))

    rows = []
    for k, t in enumerate(grid):
        t = float(t)
        if k:
            end = theta + integral(float(grid[k - 1]), t)
            s = follower_along(model.program, s, theta, end, model.c)  # the same play operator as the FMU
            theta = end
        # At an input's discontinuity (a kink or a jump of omega_ref) the outputs are its left limit, the interval
        # that ends at t, as a co-simulation step that ends there (docs/model.md 8.1); at t = 0 the first piece.
        omega = omega_ref.left_value(t) if k else omega_ref.value(t)
        omega_dot = omega_ref.left_slope(t) if k else omega_ref.slope(t)
        motion = speed_motion(omega, omega_dot, t) if k else omega
        if motion == 0.0:  # at rest the follower lies on the cam where its weight pushes it
            s = rest_position(model.program.derivatives(theta)[0], model.c, model.F_gx, s)
        engaged = speed_engaged(model.program, theta, s, motion, model.c, omega_dot, model.F_gx)
        rows.append(speed_drive_outputs(model, theta, omega, omega_dot, s, engaged, sign(motion)))
        if omega_ref.value(t) == 0.0:  # at rest from t on (a stop): there from the next interval, as the FMU's input
            s = rest_position(model.program.derivatives(theta)[0], model.c, model.F_gx, s)
    return _collect(rows, grid)


# The reference of each formulation (the keys of physics.formulations.FORMULATIONS; checked by tests/tools/test_layout.py).
REFERENCES = {"consistent": _consistent, "paper": _paper, "speed": _speed}

__all__ = ["simulate_reference", "ENERGY", "OUTPUTS"]
