"""Frequency response of the drive from the motor voltage u to the rotor's and the cam's speed.

Two operating points (docs/control.md section 5, docs/model.md section 12.3):

- **a frozen cam angle** theta0: the drive held at rest there by the voltage u0 that balances
  gravity, without shaft and guide friction and without backlash (Coulomb friction and a gap
  have no small-signal linearisation at rest; the response says it switched them off);
- **a mean speed**: the drive turning under a constant u0 (its scene's voltage); the response
  is the first harmonic at the excitation frequency, averaged over the turns the window spans.

``measured_response`` runs the C engine (DriveSimulator.run) with u = u0 + a sin(2 pi f t), held
over HOLDS_PER_PERIOD steps per period, each split into OUTPUTS_PER_HOLD communication steps, lets
it settle for the longer of SETTLE_PERIODS periods and SETTLE_TIME_CONSTANTS time constants of the
slowest pole of the linear model, and fits a + b t + c cos + d sin to the speeds over
MEASURE_PERIODS periods. The input's first harmonic is that of the staircase actually applied
(exact), so the hold's half-step delay is not mistaken for the drive's.

``analytic_response`` is the linearised two-mass system at the frozen angle (docs/model.md
12.3) as a state-space model, H(j w) = C (j w I - A)^-1 B, evaluated with numpy.
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any, Mapping, Sequence

import numpy as np

from ..physics.drive import DriveModel

HOLDS_PER_PERIOD = 32  # input values per excitation period (a staircase, as a co-simulation host applies it)
OUTPUTS_PER_HOLD = 4  # communication steps per held value: the staircase's harmonics do not alias onto f
SETTLE_PERIODS = 20  # periods before the measurement, at least
SETTLE_TIME_CONSTANTS = 8.0  # time constants of the slowest pole of the linear model, at least
MEASURE_PERIODS = 10  # periods in the fit
FROZEN_OFF = {"shaft_friction": False, "guide_friction": False, "backlash": False}


@dataclass
class Response:
    """H(j 2 pi f) from u [V] to the rotor's speed omega_m and the cam's omega [rad/s per V]."""

    f: np.ndarray  # Hz
    motor: np.ndarray  # complex, (rad/s)/V
    cam: np.ndarray  # complex, (rad/s)/V
    u0: float  # V, the operating point's voltage
    note: str  # what the operating point is and what was switched off


def frozen_parameters(params: Mapping[str, Any] | None, theta0: float) -> tuple[dict[str, Any], float]:
    """The parameters of the drive held at theta0 [rad] (friction and backlash off) and the voltage u0 [V] that
    holds it there against gravity; ValueError when gravity's stiffness makes that equilibrium unstable."""
    p = dict(params or {}, **FROZEN_OFF, theta0=theta0, omega0=0.0)
    model = DriveModel(p)
    _, s1, s2, _ = model.program.derivatives(theta0)
    k_g = -model.F_gx * s2
    if k_g < -1e-12:  # N m/rad: a rounding remainder of a horizontal mounting (F_gx ~ 1e-16 G) is no stiffness
        raise ValueError(f"theta0 = {theta0!r} rad: gravity's stiffness there is k_g = -F_gx s'' = {k_g:.4g} N m/rad "
                         "< 0, the cam would fall away from a standstill (choose an angle where k_g >= 0, or "
                         "another mounting)")
    u0 = model.R * (-model.F_gx * s1) / model.c_m
    if model.L > 0.0:
        p["i0"] = u0 / model.R
    return p, u0


def linear_model(params: Mapping[str, Any] | None, theta0: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(A, B, C) of the drive linearised at rest at theta0 [rad] without friction (docs/model.md 12.3): states
    (theta - theta0, omega, phi, omega_m[, i]); input u [V]; outputs (omega_m, omega) [rad/s]. A rigid shaft
    is the one-mass limit: states (theta - theta0, omega[, i]), both outputs omega."""
    model = DriveModel(dict(params or {}, **FROZEN_OFF))
    _, s1, s2, _ = model.program.derivatives(theta0)
    J_c = model.J_0 + model.m * s1 * s1
    k_g = -model.F_gx * s2
    R, L, c_e, c_m = model.R, model.L, model.c_e, model.c_m
    damping = 0.0 if L > 0.0 else c_m * c_e / R  # L = 0: the back-EMF's torque -c_m c_e omega_m / R
    gain = 0.0 if L > 0.0 else c_m / R  # L = 0: the motor's torque per volt
    if model.compliant:
        k, d, J_m = model.k_shaft, model.d_shaft, model.J_m
        A = [[0.0, 1.0, 0.0, 0.0],
             [-k_g / J_c, -d / J_c, k / J_c, d / J_c],
             [0.0, -1.0, 0.0, 1.0],
             [0.0, d / J_m, -k / J_m, -(d + damping) / J_m]]
        B = [0.0, 0.0, 0.0, gain / J_m]
        C = [[0.0, 0.0, 0.0, 1.0], [0.0, 1.0, 0.0, 0.0]]
        motor_row, speed = 3, 3
    else:
        A = [[0.0, 1.0], [-k_g / J_c, -damping / J_c]]
        B = [0.0, gain / J_c]
        C = [[0.0, 1.0], [0.0, 1.0]]
        motor_row, speed = 1, 1
    if L > 0.0:  # the current as a state: L di/dt = u - R i - c_e omega_m; its torque c_m i on the rotor
        n = len(A)
        A = [row + [0.0] for row in A] + [[0.0] * (n + 1)]
        A[motor_row][n] = c_m / (model.J_m if model.compliant else J_c)
        A[n][speed] = -c_e / L
        A[n][n] = -R / L
        B = B + [1.0 / L]
        C = [row + [0.0] for row in C]
    return np.array(A), np.array(B), np.array(C)


def analytic_response(params: Mapping[str, Any] | None, theta0: float, f: Sequence[float]) -> Response:
    """H(j 2 pi f) of the linearised drive at the frozen angle theta0 [rad] (docs/model.md 12.3)."""
    A, B, C = linear_model(params, theta0)
    f = np.asarray(f, dtype=float)
    eye = np.eye(len(A))
    H = np.array([C @ np.linalg.solve(2j * math.pi * fk * eye - A, B) for fk in f])
    _, u0 = frozen_parameters(params, theta0)
    return Response(f, H[:, 0], H[:, 1], u0, f"linearised at rest at theta0 = {theta0:.6g} rad")


def settle_time(params: Mapping[str, Any] | None, theta0: float) -> float:
    """SETTLE_TIME_CONSTANTS time constants [s] of the slowest decaying pole of the linear model at theta0."""
    rates = [-ev.real for ev in np.linalg.eigvals(linear_model(params, theta0)[0]) if ev.real < -1e-9]
    return SETTLE_TIME_CONSTANTS / min(rates) if rates else 0.0


def _harmonic(t: np.ndarray, y: np.ndarray, w: float) -> complex:
    """The complex amplitude Y of y ~ a + b t + Re(Y e^(j w t)) fitted by least squares [unit of y]."""
    X = np.column_stack([np.ones_like(t), t - t[0], np.cos(w * t), np.sin(w * t)])
    coef = np.linalg.lstsq(X, y, rcond=None)[0]
    return complex(coef[2], -coef[3])


def _staircase_harmonic(starts: np.ndarray, hold: float, u: np.ndarray, w: float, span: float) -> complex:
    """The complex amplitude at w [rad/s] of the staircase u held from each start for ``hold`` [s] (exact)."""
    integral = np.sum(u * np.exp(-1j * w * starts)) * (1.0 - np.exp(-1j * w * hold)) / (1j * w)
    return 2.0 * integral / span


def measured_response(params: Mapping[str, Any] | None, f: Sequence[float], theta0: float | None = None,
                      u0: float | None = None, amplitude: float = 1e-3) -> Response:
    """H(j 2 pi f) measured on the C engine by small-signal simulation (module docstring).

    ``theta0`` [rad]: the frozen-angle operating point (friction and backlash off, u0 from gravity); else the
    drive turning under ``u0`` [V] with everything its parameters model. ``amplitude`` [V] of the sine."""
    from ..engine.simulator import DriveSimulator

    if not (math.isfinite(amplitude) and amplitude > 0.0):
        raise ValueError(f"amplitude = {amplitude!r} V: allowed > 0")
    if theta0 is not None:
        p, u0 = frozen_parameters(params, theta0)
        settle = settle_time(params, theta0)
        note = f"frozen at theta0 = {theta0:.6g} rad, held by u0 = {u0:.6g} V; shaft and guide friction and backlash off"
    else:
        if u0 is None:
            raise ValueError("give the operating point: theta0 (a frozen angle) or u0 (a mean speed)")
        p = dict(params or {})
        model = DriveModel(p)
        _, _, _, _ = model.program.derivatives(0.0)
        J_heavy = max(model.J_0 + model.m * model.program.derivatives(t)[1] ** 2
                      for t in np.linspace(0.0, 2.0 * math.pi, 361))
        settle = SETTLE_TIME_CONSTANTS * model.R * (J_heavy + (model.J_m if model.compliant else 0.0)) / (
            model.c_e * model.c_m)
        note = f"turning under u0 = {u0:.6g} V (first harmonic averaged over the window)"
    motor, cam = [], []
    for fk in np.asarray(f, dtype=float):
        if not (math.isfinite(fk) and fk > 0.0):
            raise ValueError(f"frequency {fk!r} Hz: allowed > 0")
        period = 1.0 / fk
        hold = period / HOLDS_PER_PERIOD
        h = hold / OUTPUTS_PER_HOLD
        settle_holds = HOLDS_PER_PERIOD * max(SETTLE_PERIODS, math.ceil(settle / period))
        n_holds = settle_holds + HOLDS_PER_PERIOD * MEASURE_PERIODS
        starts = np.arange(n_holds) * hold
        w = 2.0 * math.pi * fk
        u = u0 + amplitude * np.sin(w * (starts + 0.5 * hold))  # the sine sampled mid-hold
        n = n_holds * OUTPUTS_PER_HOLD
        t0 = np.arange(n) * h
        table = np.column_stack([t0, np.full(n, h), np.repeat(u, OUTPUTS_PER_HOLD), np.ones(n), np.zeros(n)])
        out = DriveSimulator(p).run(table)
        window = slice(settle_holds * OUTPUTS_PER_HOLD, n)
        t_end = t0[window] + h
        span = MEASURE_PERIODS * period
        U = _staircase_harmonic(starts[settle_holds:], hold, u[settle_holds:], w, span)
        from ..physics.variables import OUTPUT_NAMES

        Ym = _harmonic(t_end, out[window, OUTPUT_NAMES.index("omega_m")], w)
        Yc = _harmonic(t_end, out[window, OUTPUT_NAMES.index("omega")], w)
        motor.append(Ym / U)
        cam.append(Yc / U)
    return Response(np.asarray(f, dtype=float), np.array(motor), np.array(cam), float(u0), note)


__all__ = ["Response", "analytic_response", "frozen_parameters", "linear_model", "measured_response",
           "settle_time"]
