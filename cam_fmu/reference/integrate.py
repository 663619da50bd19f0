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

from ..physics.signals import Signal, constant
from ..physics.contact import follower_along, rest_position, speed_engaged
from ..physics.drive import DriveModel, sign
from ..physics.formulations import formulation_name
from ..physics.formulations.consistent import EVENT_NAME, EVENTS, HybridDrive
from ..physics.formulations.paper import PaperScheme, calculation_steps
from ..physics.formulations.speed import speed_drive_outputs
from ..physics.follower_kind import FollowerKind
from ..physics.kind_drive import KindDriveModel
from ..physics.modes import Event
from ..physics.parameters import ParameterError, resolve
from ..physics.train import Train
from ..physics.variables import INPUT_STARTS, OUTPUTS
from .flight import follower_speed_reference, speed_motion
from .follower_kind import kind_reference, with_arm_angle, with_arm_end
from .hybrid import ENERGY, VoltageRun, collect, event, next_breakpoint, piece_input
from .train_flight import train_follower_reference, train_speed_follower_reference
from .train_speed import speed_train_reference
from .train_voltage import voltage_train_reference
from .voltage_flight import follower_voltage_reference



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
    train: Train | None = None,
    follower: FollowerKind | None = None,
) -> dict[str, np.ndarray]:
    """Run the drive from 0 to ``stop_time`` [s]; outputs every ``output_interval`` [s].

    ``train``: the follower train (physics.train.Train, docs/model.md 14.6; None: the parameters' k_train, d_train,
    m_end); k_train = 0 is the rigid drive, bit for bit. With one the outputs add reference.train_speed.TRAIN_INTEGRALS
    (the speed drive; the voltage drive, with its friction and a compliant shaft, reference/train_voltage.py; with a
    follower of its own, reference/train_flight.py); a translating flat or an arm on the cam runs the same references
    with physics.kind_drive.KindDriveModel (its P carries F_train; an arm's torsional train from its parameters
    k_train_arm, d_train_arm, J_end, in lift units); a Train given along X to an arm is refused naming follower_type.

    ``follower``: the follower's kind (physics.follower_kind.FollowerKind, docs/model.md 16); None or
    'translating_roller' is today's drive, bit for bit. Another kind runs in the consistent formulation and the
    speed drive (reference/follower_kind.py), its outputs add reference.follower_kind.KIND_OUTPUTS. None: the
    parameters' kind (follower_type and an arm's fields), as the engine takes it; given with a parameter kind other
    than the default, the two must be equal."""
    named = FollowerKind.from_parameters(resolve(params))
    if follower is None:
        follower = named
    elif not named.default and named != follower:
        raise ParameterError(f"follower={follower!r} and the parameters' kind {named!r} differ: give one of them")
    if not follower.default:
        model = KindDriveModel(params, follower)  # refuses k_train on an arm by its follower_type
        grid, u = output_grid(stop_time, output_interval), u or constant(INPUT_STARTS["u"])
        omega_ref = omega_ref or constant(INPUT_STARTS["omega_ref"])
        options = {"rtol": rtol, "atol": atol, "energy": energy, "method": method}
        train = model.train if train is None else train
        if train.active:
            return with_arm_end(model, _kind_train(model, grid, u, omega_ref, train, options))
        return with_arm_end(model, kind_reference(model, grid, u, omega_ref, options))
    model = DriveModel(params)
    u = u or constant(INPUT_STARTS["u"])
    omega_ref = omega_ref or constant(INPUT_STARTS["omega_ref"])
    grid = output_grid(stop_time, output_interval)
    options = {"rtol": rtol, "atol": atol, "energy": energy, "method": method}
    train = model.train if train is None else train   # the parameters' (k_train, d_train, m_end) unless given
    if train.active:
        run = TRAIN_REFERENCES.get(formulation_name(model))
        if run is None:
            raise ParameterError("the follower train runs in the consistent formulation and the speed drive only "
                                 f"(parameter 'formulation' = {model.formulation!r})")
        return run(model, grid, u, omega_ref, train, options)
    return REFERENCES[formulation_name(model)](model, grid, u, omega_ref, options)


def output_grid(stop_time: float, output_interval: float) -> np.ndarray:
    """The output times [s]: 0, output_interval, .., and stop_time (a last, shorter interval ends there, as fmpy's)."""
    if not (stop_time > 0.0 and output_interval > 0.0):
        raise ValueError(f"stop_time = {stop_time} s and output_interval = {output_interval} s must be > 0")
    n = int(math.floor(stop_time / output_interval * (1.0 + 1e-12)))
    grid = np.arange(n + 1) * output_interval
    if stop_time - grid[-1] > 1e-9 * stop_time:  # a last, shorter interval ends at stop_time, as fmpy does
        grid = np.append(grid, stop_time)
    return grid


class _Consistent(VoltageRun):
    """The rigid (and compliant) drive through the one hybrid loop: ``HybridDrive``'s events and transitions."""

    label = "reference integration"

    def __init__(self, model: DriveModel, u: Signal, rtol: float, atol: float, energy: bool, method: str | None) -> None:
        super().__init__(model, u, rtol, atol, energy, method)
        self.model, self.hybrid = model, HybridDrive(model)
        self.target = math.nan  # rad, the breakpoint ahead of the piece (none while stuck)

    def run(self, grid: np.ndarray) -> dict[str, np.ndarray]:
        p = self.model.params
        y, mode = self.hybrid.initial(p["theta0"], p["omega0"], p["i0"])
        y = list(y) + ([0.0] * len(ENERGY) if self.energy else [])
        return self.pieces(grid, 0.0, y, mode, [b for b in self.u.breaks if 0.0 < b < float(grid[-1])])

    def _near(self, t: float) -> float:
        return 1e-12

    def _inside(self, t: float) -> float:
        return 1e-12 * max(1.0, t)

    def _origin(self, y: list) -> float:
        # theta is integrated relative to the last whole turn: rtol then acts on an angle below 4 pi, not on the
        # unbounded theta (long runs keep their accuracy).
        return 2.0 * math.pi * math.floor(y[0] / (2.0 * math.pi))

    def _rows_first(self, t: float, after_event: bool) -> bool:
        # Outputs due at an input's break: its left limit, the mode and the input before it (docs/model.md 8.1), as
        # a co-simulation step that ends there; elsewhere the state after the restart's transitions.
        return not after_event and t > 0.0 and t in self.u.breaks

    def _settle(self, t: float, y: list, mode, after_event: bool):
        """At the start and at an input's break the break-away rule and the friction branch (not after an event:
        its transition settled the mode, and settling again at a located break-away, margin ~ -1e-17, re-sticks
        it); then every event function already below zero (it jumped there, which solve_ivp's crossing search cannot
        see: the side force N_r at a breakpoint where s'' jumps, every row of a motion table) fires now, as the C
        engine's at a step's start."""
        hybrid, u_now, n = self.hybrid, self.u.value(t), self.hybrid.size
        if not after_event:
            hybrid.settle(y, u_now, mode)
        while True:
            names = hybrid.event_names(mode)
            due = next((name for name, value in zip(names, hybrid.event_values(y[:n], u_now, mode)) if value < 0.0),
                       None)
            if due is None:
                return mode, y
            self._stall(t)
            hybrid.apply_event(y, u_now, mode, due)

    def _piece(self, t: float, y: list, mode):
        hybrid, n, u_at = self.hybrid, self.hybrid.size, piece_input(self.u, self.piece_end)
        base = self._origin(y)

        def value(k: int):
            return lambda t, y: hybrid.event_values([y[0] + base, *y[1:n]], u_at(t)[0], mode)[k]
        events = [event(EVENTS[name], value(k)) for k, name in enumerate(hybrid.event_names(mode))]
        if not mode.stuck:
            target, direction = next_breakpoint(self.breakpoints, y[0], mode.direction) - base, mode.direction
            self.target = target + base
            events.append(event(Event.BREAKPOINT, lambda t, y: direction * (target - y[0])))
        atol = [self.atol] * len(y)
        if self.energy:
            atol[-len(ENERGY):] = [self.atol * 1e-2] * len(ENERGY)
        return events, self._rhs(mode, base), {"method": self.method, "atol": atol}

    def _event(self, t: float, y: list, mode, kind: Event):
        """Any event: at the breakpoint, on from just past it, as the C engine ends its step there (a root located
        a rounding short of it lies where s'' is still the piece's before, and an event caused by the jump there,
        N_r's sign at a motion table's row, would be applied on the wrong side of its cause); then HybridDrive's
        transition."""
        target = self.target
        if not mode.stuck and abs(target - y[0]) <= 1e-12 * max(1.0, abs(target)):
            past = target + mode.direction * 1e-15 * max(1.0, abs(target))
            if mode.direction * (past - y[0]) > 0.0:
                y[0] = past
        if kind is not Event.BREAKPOINT:
            self.hybrid.apply_event(y, self.u.value(t), mode, EVENT_NAME[kind])
        return mode, y

    TRANSITIONS = dict.fromkeys((*EVENTS.values(), Event.BREAKPOINT), _event)

    def _rhs(self, mode, base: float):
        hybrid, model, n = self.hybrid, self.model, self.hybrid.size
        energy, u_at = self.energy, piece_input(self.u, self.piece_end)
        side = mode.side if hybrid.guide_side and not mode.stuck else 0.0  # the friction's branch held

        def rhs(t, y):
            u_t = u_at(t)[0]
            state = [y[0] + base, *y[1:n]]
            dy = list(hybrid.derivative(state, u_t, mode))
            if energy:
                i = hybrid.current(state, u_t)
                omega = 0.0 if mode.stuck else y[1]
                load = model.load(state[0], omega, dy[1], mode.direction, mode.contact != 0)
                slip = hybrid.motor_speed(state) - omega
                dy += [u_t * i, model.R * i * i, model.M_f * abs(omega), model.friction_power(load, side),
                       model.d_shaft * slip * slip]
            return dy

        return rhs

    def _row(self, t: float, y, mode, left: bool) -> dict[str, float]:
        n = self.hybrid.size
        row = self.hybrid.outputs(y[:n], self.u.left_value(t) if left else self.u.value(t), mode)
        return row | (dict(zip(ENERGY, y[-len(ENERGY):])) if self.energy else {})


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
    return collect(rows, grid)


def _speed(model: DriveModel, grid: np.ndarray, u: Signal, omega_ref: Signal, options: dict) -> dict[str, np.ndarray]:
    """Imposed speed: theta = theta0 + int omega_ref dt (exact for piecewise-linear signals)."""
    if model.free_follower:  # the follower's own state
        return follower_speed_reference(model, grid, omega_ref, options["rtol"], options["atol"])
    return collect(_speed_rows(model, grid, omega_ref), grid)


def _speed_rows(model: DriveModel, grid: np.ndarray, omega_ref: Signal) -> list[dict[str, float]]:
    """The speed drive's output rows on ``grid`` (the follower on the cam)."""
    p = model.params
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
    return rows


def _speed_train(model: DriveModel, grid: np.ndarray, u: Signal, omega_ref: Signal, train: Train,
                 options: dict, runner: type | None = None) -> dict[str, np.ndarray]:
    """The speed drive with a train; a follower of its own runs ``runner`` (None: the roller's)."""
    if model.free_follower:  # the train on the follower's own state (docs/model.md 14.6)
        return train_speed_follower_reference(model, grid, omega_ref, options, train, runner)
    return speed_train_reference(model, grid, omega_ref, train, options["rtol"], options["atol"])


def _voltage_train(model: DriveModel, grid: np.ndarray, u: Signal, omega_ref: Signal, train: Train,
                   options: dict, runner: type | None = None) -> dict[str, np.ndarray]:
    """The consistent voltage drive with a train; a follower of its own runs ``runner`` (None: the roller's)."""
    if model.free_follower:  # the train on the follower's own state (docs/model.md 14.6)
        return train_follower_reference(model, grid, u, options, train, runner=runner)
    return voltage_train_reference(model, grid, u, train, options["rtol"], options["atol"], options["method"])


def _kind_train(model: KindDriveModel, grid: np.ndarray, u: Signal, omega_ref: Signal, train: Train,
                options: dict) -> dict[str, np.ndarray]:
    """The train on another kind on the cam (docs/model.md 14.6, 16): the roller's train references with the kind's
    model, whose P (and so its friction mu |P| lambda) carries F_train (an arm's torsional train in the law's lift
    units, its torque F_train / scale); psi, psi_dot the arm's (0 for the flat). A Train given to an arm beside its
    parameters is refused: an arm's train is torsional, its parameters k_train_arm, d_train_arm, J_end."""
    if model.kind.oscillating and train is not model.train:
        raise ParameterError(f"a follower train given along X does not run with follower_type "
                             f"{model.kind.follower_type!r}: an arm's train is torsional, set by the parameters "
                             f"'k_train_arm', 'd_train_arm', 'J_end'")
    run = TRAIN_REFERENCES.get(formulation_name(model))
    if run is None:
        raise ParameterError("the follower train runs in the consistent formulation and the speed drive only "
                             f"(parameter 'formulation' = {model.formulation!r})")
    if model.free_follower:   # the kind's body of its own carrying the train (its rows hold psi, psi_dot)
        from .kind_flight import KindTrainFollowerRun, KindTrainSpeedFollowerRun
        runner = KindTrainFollowerRun if run is _voltage_train else KindTrainSpeedFollowerRun
        return run(model, grid, u, omega_ref, train, options, runner)
    return with_arm_angle(model, run(model, grid, u, omega_ref, train, options))


# The reference with a follower train, by formulation (docs/model.md 14.6; the paper's scheme has none).
TRAIN_REFERENCES = {"consistent": _voltage_train, "speed": _speed_train}
# The reference of each formulation (the keys of physics.formulations.FORMULATIONS; checked by tests/tools/test_layout.py).
REFERENCES = {"consistent": _consistent, "paper": _paper, "speed": _speed}

__all__ = ["simulate_reference", "ENERGY", "OUTPUTS"]
