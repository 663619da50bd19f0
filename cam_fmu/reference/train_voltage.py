"""The voltage drive with the follower train (docs/model.md 14.6), without friction: the cam, the motor and the end
mass integrated together by scipy.

y = (theta, omega, i, x_e, v_e, W_train, E_train_damp, E_in, E_copper): the rigid drive's equation (5.1) with the
train's force F_train on the follower (``DriveModel.omega_dot``'s ``axial``), i a state with L > 0 (held, and
quasi-static, with L = 0), the end mass's two states and four energy integrals: W_train = int F_train v dt,
E_train_damp = int d_train (v - v_e)^2 dt, E_in = int u i dt, E_copper = int R i^2 dt. Without friction the shaft
never sticks and nothing switches but the profile (s'', s''' jump at its breakpoints) and the input's breaks: DOP853
(Radau with a fast electrical pole, as the rigid reference) stops at those and where omega crosses 0 (the way the
next breakpoint lies turns there). Friction (shaft or guide), a clearance, a compliant shaft and a follower of its
own are refused with that reason: their events do not carry the train yet.
"""
from __future__ import annotations

import math

import numpy as np

from ..physics.drive import DriveModel
from ..physics.parameters import ParameterError
from ..physics.signals import Signal
from ..physics.train import Train, end_weight
from ..physics.variables import output_record
from .hybrid import collect, next_breakpoint

__all__ = ["voltage_train_reference"]

THETA, OMEGA, CURRENT, X_E, V_E = range(5)


def _check(model: DriveModel) -> None:
    refused = [name for name, on in (("'M_f' (shaft friction)", model.M_f != 0.0),
                                     ("'mu' (guide friction)", model.mu != 0.0), ("'c' (clearance)", model.c != 0.0),
                                     ("'k_shaft' (compliant shaft)", model.compliant),
                                     ("'closure' (a follower of its own)", model.free_follower)) if on]
    if refused:
        raise ParameterError(f"the follower train in the voltage drive runs without friction, clearance, compliant "
                             f"shaft or follower of its own so far: parameters {', '.join(refused)} must be off "
                             f"(their events do not carry the train yet)")


def voltage_train_reference(model: DriveModel, grid: np.ndarray, u: Signal, train: Train, rtol: float,
                            atol: float, method: str | None) -> dict[str, np.ndarray]:
    """The voltage drive with ``train`` on ``grid`` [s]: the drive's outputs with F_train in the load, the train's
    outputs (reference.train_speed.TRAIN_OUTPUTS) and E_in, E_copper [J]."""
    from scipy.integrate import solve_ivp

    _check(model)
    p, program, motor = model.params, model.program, model.motor
    L = model.L
    method = method or ("Radau" if L > 0.0 and L / model.R < 1e-3 else "DOP853")
    breakpoints = sorted(set(program.breakpoints()) | {0.0}) + [2.0 * math.pi]
    F_ex = end_weight(train, p)
    k, d, m_e = train.k_train, train.d_train, train.m_end
    theta0, omega0 = p["theta0"], p["omega0"]
    s0, s1_0 = program.derivatives(theta0)[:2]
    y = np.array([theta0, omega0, p["i0"] if L > 0.0 else 0.0, s0 + F_ex / k, s1_0 * omega0, 0.0, 0.0, 0.0, 0.0])

    def derivative(y, u_t):
        theta, omega = y[THETA], y[OMEGA]
        i = y[CURRENT] if L > 0.0 else motor.quasi_static_current(u_t, omega)
        s, s1 = program.derivatives(theta)[:2]
        v = s1 * omega
        F = k * (s - y[X_E]) + d * (v - y[V_E])
        omega_dot = model.omega_dot(theta, omega, model.c_m * i, 1.0, True, 0.0, F)
        di = motor.current_rate(u_t, i, omega) if L > 0.0 else 0.0
        return [omega, omega_dot, di, y[V_E], (F + F_ex) / m_e, F * v, d * (v - y[V_E]) ** 2, u_t * i,
                model.R * i * i]

    states = np.empty((len(grid), len(y)))
    states[0] = y
    stop = float(grid[-1])
    times = sorted({0.0, stop, *(b for b in u.breaks if 0.0 < b < stop)})
    for a, b in zip(times[:-1], times[1:]):
        u_a, slope = u.value(a), u.slope(a)

        def rhs(t, y, a=a, u_a=u_a, slope=slope):
            return derivative(y, u_a + slope * (t - a))

        def turning(t, y):
            return y[OMEGA]
        turning.terminal, turning.direction = True, 0
        t = a
        while t < b:
            omega = y[OMEGA]
            direction = math.copysign(1.0, omega if omega else rhs(t, y)[OMEGA] or 1.0)
            target = next_breakpoint(breakpoints, y[THETA], direction)

            def crossing(t, y, target=target, direction=direction):
                return direction * (target - y[THETA])
            crossing.terminal, crossing.direction = True, -1
            events = [crossing] + ([turning] if omega else [])
            sol = solve_ivp(rhs, (t, b), y, method=method, rtol=rtol, atol=atol, events=events, dense_output=True)
            if sol.status < 0:
                raise RuntimeError(f"train reference failed at t = {t} s: {sol.message}")
            t_end = float(sol.t[-1])
            done = (grid > t) & (grid <= t_end)
            if done.any():
                states[done] = sol.sol(grid[done]).T
            y = sol.y[:, -1].copy()
            if sol.status == 1 and len(sol.t_events[0]):  # at a breakpoint: on from just past it
                y[THETA] = target + direction * 1e-15 * max(1.0, abs(target))
            elif sol.status == 1:  # omega crossed 0: exactly 0 there, the next breakpoint lies the other way
                y[OMEGA] = 0.0
            t = t_end if t_end > t else b
    rows = []
    for t, y in zip(grid, states):
        t = float(t)
        u_t = u.left_value(t) if t > 0.0 and t in u.breaks else u.value(t)
        rows.append(_row(model, train, F_ex, y, u_t))
    return collect(rows, grid)


def _row(model: DriveModel, train: Train, F_ex: float, y: np.ndarray, u_t: float) -> dict[str, float]:
    theta, omega = float(y[THETA]), float(y[OMEGA])
    i = float(y[CURRENT]) if model.L > 0.0 else model.motor.quasi_static_current(u_t, omega)
    s, s1 = model.program.derivatives(theta)[:2]
    F = train.force(s, s1 * omega, float(y[X_E]), float(y[V_E]))
    direction = 1.0 if omega >= 0.0 else -1.0
    omega_dot = model.omega_dot(theta, omega, model.c_m * i, direction, True, 0.0, F)
    load = model.load(theta, omega, omega_dot, direction, True, F)
    row = output_record(omega=omega, theta=theta, s=load.s_cam, i=i, M=load.M, J=load.J, v=load.v, a=load.a,
                        alpha=load.alpha, s_cam=load.s_cam, voltage=u_t, N_contact=load.N, theta_m=theta,
                        omega_m=omega, M_shaft=0.0)
    return row | {"s_end": float(y[X_E]), "v_end": float(y[V_E]), "a_end": (F + F_ex) / train.m_end, "F_train": F,
                  "W_train": float(y[5]), "E_train_damp": float(y[6]), "E_in": float(y[7]), "E_copper": float(y[8])}
