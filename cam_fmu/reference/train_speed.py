"""The speed drive with the follower train (docs/model.md 14.6): the end mass integrated by scipy under the cam's
imposed motion, its reaction in the load torque.

The cam angle is imposed (theta' = omega_ref, linear on each input piece), the follower rides on the cam
(closure kinematic, no clearance), so the drive's own states are the end mass's: y = (theta, x_e, v_e, W_train,
E_train_damp), with the work the follower does on the train W_train = int F_train v dt and the damper's loss
E_train_damp = int d_train (v - v_e)^2 dt. DOP853 at the reference's tolerances, stopping at every input break, where
omega_ref crosses 0 and at every profile breakpoint (s'' and s''' jump there). The rigid drive's outputs come from
``speed_drive_outputs`` with the train's force on the follower (``axial``), so the load torque, current and voltage
carry F_train s' (a translating flat's KindDriveModel: in its P, so in its friction too).
"""
from __future__ import annotations

import math

import numpy as np

from ..physics.drive import DriveModel
from ..physics.formulations.speed import speed_drive_outputs
from ..physics.parameters import ParameterError
from ..physics.signals import Signal
from ..physics.train import Train, end_weight
from .flight import speed_motion
from .hybrid import collect, next_breakpoint

__all__ = ["TRAIN_INTEGRALS", "speed_train_reference"]

# The columns a run with a train adds beside the outputs (s_end, v_end, a_end, F_train: physics.variables.OUTPUTS)
# [unit, meaning].
TRAIN_INTEGRALS: tuple[tuple[str, str, str], ...] = (
    ("W_train", "J", "work the follower has done on the train, int F_train v dt"),
    ("E_train_damp", "J", "energy the train's damper has dissipated, int d_train (v - v_e)^2 dt"),
)


def _pieces(omega_ref: Signal, stop: float) -> list[tuple[float, float]]:
    """[a, b] intervals on which omega_ref is linear and keeps its sign."""
    times = sorted({0.0, stop, *(b for b in omega_ref.breaks if 0.0 < b < stop)})
    pieces = []
    for a, b in zip(times[:-1], times[1:]):
        w, slope = omega_ref.value(a), omega_ref.slope(a)
        if slope != 0.0 and a < a - w / slope < b and w != 0.0:
            pieces += [(a, a - w / slope), (a - w / slope, b)]
        else:
            pieces.append((a, b))
    return pieces


def speed_train_reference(model: DriveModel, grid: np.ndarray, omega_ref: Signal, train: Train, rtol: float,
                          atol: float) -> dict[str, np.ndarray]:
    """The speed drive with ``train`` on ``grid`` [s]: the drive's outputs (the train's among them) with F_train in
    the load, and TRAIN_INTEGRALS."""
    from scipy.integrate import solve_ivp

    if model.free_follower or model.c != 0.0:
        raise ParameterError("the follower train runs with the follower on the cam only (closure 'kinematic', or "
                             "'form' without clearance): parameter 'c' must be 0 and 'closure' not 'spring' "
                             "(a train on a follower of its own runs in reference/train_flight.py)")
    p, program = model.params, model.program
    breakpoints = sorted(set(program.breakpoints()) | {0.0}) + [2.0 * math.pi]
    F_ex = end_weight(train, p)
    k, d, m_e = train.k_train, train.d_train, train.m_end
    theta0 = p["theta0"]
    s0, s1_0 = program.derivatives(theta0)[:2]
    y = np.array([theta0, s0 + F_ex / k, s1_0 * omega_ref.value(0.0), 0.0, 0.0])
    states = np.empty((len(grid), 5))
    states[0] = y
    stop = float(grid[-1])
    for a, b in _pieces(omega_ref, stop):
        w_a, slope = omega_ref.value(a), omega_ref.slope(a)
        direction = math.copysign(1.0, w_a + slope * 0.5 * (b - a)) if (w_a or slope) else 0.0

        def rhs(t, y, a=a, w_a=w_a, slope=slope):
            omega = w_a + slope * (t - a)
            s, s1 = program.derivatives(y[0])[:2]
            v = s1 * omega
            F = k * (s - y[1]) + d * (v - y[2])
            return [omega, y[2], (F + F_ex) / m_e, F * v, d * (v - y[2]) ** 2]

        t = a
        while t < b:
            events = []
            if direction:
                target = next_breakpoint(breakpoints, y[0], direction)

                def crossing(t, y, target=target):
                    return direction * (target - y[0])
                crossing.terminal, crossing.direction = True, -1
                events.append(crossing)
            inside = (grid > t) & (grid <= b)
            sol = solve_ivp(rhs, (t, b), y, method="DOP853", rtol=rtol, atol=atol, events=events, dense_output=True)
            if sol.status < 0:
                raise RuntimeError(f"train reference failed at t = {t} s: {sol.message}")
            t_end = float(sol.t[-1])
            done = inside & (grid <= t_end)
            if done.any():
                states[done] = sol.sol(grid[done]).T
            y = sol.y[:, -1].copy()
            if sol.status == 1:  # at a breakpoint: on from just past it, as the rigid reference
                y[0] = target + direction * 1e-15 * max(1.0, abs(target))
            t = t_end if t_end > t else b
    rigid_and_train = []
    for row, (th, x_e, v_e, work, loss) in zip(_rigid(model, grid, omega_ref), states):
        s, v = row["s"], row["v"]
        F = train.force(s, v, x_e, v_e)
        a_e = (F + F_ex) / m_e
        F_rate = k * (v - v_e) + d * (row["a"] - a_e)
        t = float(row["_t"])
        omega = omega_ref.left_value(t) if t else omega_ref.value(t)
        omega_dot = omega_ref.left_slope(t) if t else omega_ref.slope(t)
        direction = math.copysign(1.0, speed_motion(omega, omega_dot, t)) if speed_motion(omega, omega_dot, t) else 0
        out = speed_drive_outputs(model, row["theta"], omega, omega_dot, s, True, direction, F, F_rate)
        rigid_and_train.append(out | {"s_end": x_e, "v_end": v_e, "a_end": a_e, "F_train": F, "W_train": work,
                                      "E_train_damp": loss})
    return collect(rigid_and_train, grid)


def _rigid(model: DriveModel, grid: np.ndarray, omega_ref: Signal) -> list[dict[str, float]]:
    """The rigid drive's rows (theta, s, v, a at each grid time) from the reference's own speed drive."""
    from .integrate import _speed_rows

    return [row | {"_t": float(t)} for row, t in zip(_speed_rows(model, grid, omega_ref), grid)]
