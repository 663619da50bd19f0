"""Frequency response measured on the C engine by small-signal simulation (control.frequency has the theory:
the operating points, the linearised drive and its analytic response; docs/control.md section 5).

``measured_response`` runs the C engine (DriveSimulator.run) with u = u0 + a sin(2 pi f t), held
over HOLDS_PER_PERIOD steps per period, each split into OUTPUTS_PER_HOLD communication steps, lets
it settle for the longer of SETTLE_PERIODS periods and SETTLE_TIME_CONSTANTS time constants of the
slowest pole of the linear model, and fits a + c cos + d sin to the difference of the
speeds with and without the sine over MEASURE_PERIODS periods (at a mean speed: at least two
turns). The input's first harmonic is that of the staircase actually applied (exact), so the
hold's half-step delay is not mistaken for the drive's. The amplitude (default 1 mV) must keep
the response linear: the cam's angle excursion a |H_cam| / (2 pi f) small against the profile's
detail (at 1 mV and 1 Hz on the shipped compliant scene, 6e-4 rad).
"""
from __future__ import annotations

import math
from typing import Any, Mapping, Sequence

import numpy as np

from ..control.frequency import SETTLE_TIME_CONSTANTS, Response, frozen_parameters, settle_time
from ..fmu.engine import DriveSimulator
from ..physics.drive import DriveModel
from ..physics.variables import OUTPUT_NAMES

HOLDS_PER_PERIOD = 64  # input values per excitation period (a staircase, as a co-simulation host applies it)
# Communication steps per held value: the speeds are sampled 512 times per period. The fit's error is the
# response to the staircase's harmonics that alias onto f; it falls as 1 / samples^2 (measured on the linear
# model's exact staircase response, the rotor's speed at 5 Hz on the compliant scene: 8 % at 64 samples,
# 3.5e-3 at 256, 2.2e-4 at 1024; the cam's speed, smoother, 8e-6 from 256 on).
OUTPUTS_PER_HOLD = 8
SETTLE_PERIODS = 20  # periods before the measurement, at least
MEASURE_PERIODS = 10  # periods in the fit


def _harmonic(t: np.ndarray, y: np.ndarray, w: float) -> complex:
    """The complex amplitude Y of y ~ a + Re(Y e^(j w t)) fitted by least squares [unit of y]. Over whole periods
    of samples equally spaced, the harmonics of the staircase (64 k +- 1) are orthogonal to it; a trend term
    is not (it leaked the drive's response to the 63rd and 65th, near the shaft's resonance, into Y)."""
    X = np.column_stack([np.ones_like(t), np.cos(w * t), np.sin(w * t)])
    coef = np.linalg.lstsq(X, y, rcond=None)[0]
    return complex(coef[1], -coef[2])


def _staircase_harmonic(starts: np.ndarray, hold: float, u: np.ndarray, w: float, span: float) -> complex:
    """The complex amplitude at w [rad/s] of the staircase u held from each start for ``hold`` [s] (exact)."""
    integral = np.sum(u * np.exp(-1j * w * starts)) * (1.0 - np.exp(-1j * w * hold)) / (1j * w)
    return 2.0 * integral / span


def _table(u: np.ndarray, h: float) -> np.ndarray:
    """The engine's input table: every held value of u over OUTPUTS_PER_HOLD communication steps of h [s]."""
    n = len(u) * OUTPUTS_PER_HOLD
    return np.column_stack([np.arange(n) * h, np.full(n, h), np.repeat(u, OUTPUTS_PER_HOLD), np.ones(n), np.zeros(n)])


def _operating_point(params: Mapping[str, Any] | None, theta0: float | None, u0: float | None):
    """(parameters, u0 [V], settle time [s], window floor [s], note) of the operating point."""
    if theta0 is not None:
        p, u0 = frozen_parameters(params, theta0)
        return p, u0, settle_time(params, theta0), 0.0, (
            f"frozen at theta0 = {theta0:.6g} rad, held by u0 = {u0:.6g} V; shaft and guide friction and backlash off")
    if u0 is None or not math.isfinite(u0):
        raise ValueError("give the operating point: theta0 (a frozen angle) or a finite u0 [V] (a mean speed)")
    p = dict(params or {})
    model = DriveModel(p)
    J_heavy = max(model.J_0 + model.m * model.program.derivatives(t)[1] ** 2
                  for t in np.linspace(0.0, 2.0 * math.pi, 361)) + (model.J_m if model.compliant else 0.0)
    settle = SETTLE_TIME_CONSTANTS * model.R * J_heavy / (model.c_e * model.c_m)  # the slowest mechanical pole
    h = 1e-3
    run = DriveSimulator(p).run(_table(np.full(max(1, math.ceil(settle / h / OUTPUTS_PER_HOLD)), u0), h))
    theta = run[:, OUTPUT_NAMES.index("theta")]
    half = len(theta) // 2
    turn_rate = abs(theta[-1] - theta[half]) / ((len(theta) - half) * h) / (2.0 * math.pi)  # turns per second
    if not turn_rate > 1e-3:
        raise ValueError(f"u0 = {u0!r} V: the cam does not turn (it comes to rest); give a frozen angle instead")
    return p, u0, settle, 2.0 / turn_rate, f"turning under u0 = {u0:.6g} V at {60.0 * turn_rate:.4g} 1/min " \
        "(the first harmonic at f, averaged over at least two turns)"


def measured_response(params: Mapping[str, Any] | None, f: Sequence[float], theta0: float | None = None,
                      u0: float | None = None, amplitude: float = 1e-3) -> Response:
    """H(j 2 pi f) measured on the C engine by small-signal simulation (module docstring).

    ``theta0`` [rad]: the frozen-angle operating point (friction and backlash off, u0 from gravity); else the
    drive turning under ``u0`` [V] with everything its parameters model. ``amplitude`` [V] of the sine. Each
    frequency runs the drive twice from the same start, with and without the sine, and fits the difference:
    the operating point's own motion (the cam's turning, a settling transient) cancels exactly."""
    if not (math.isfinite(amplitude) and amplitude > 0.0):
        raise ValueError(f"amplitude = {amplitude!r} V: allowed > 0")
    p, u0, settle, window, note = _operating_point(params, theta0, u0)
    columns = [OUTPUT_NAMES.index("omega_m"), OUTPUT_NAMES.index("omega")]
    motor, cam = [], []
    for fk in np.asarray(f, dtype=float):
        if not (math.isfinite(fk) and fk > 0.0):
            raise ValueError(f"frequency {fk!r} Hz: allowed > 0")
        period = 1.0 / fk
        hold = period / HOLDS_PER_PERIOD
        h = hold / OUTPUTS_PER_HOLD
        settle_holds = HOLDS_PER_PERIOD * max(SETTLE_PERIODS, math.ceil(settle / period))
        measure_periods = max(MEASURE_PERIODS, math.ceil(window / period))
        n_holds = settle_holds + HOLDS_PER_PERIOD * measure_periods
        starts = np.arange(n_holds) * hold
        w = 2.0 * math.pi * fk
        sine = amplitude * np.sin(w * (starts + 0.5 * hold))  # the sine sampled mid-hold
        excited = DriveSimulator(p).run(_table(u0 + sine, h))[:, columns]
        base = DriveSimulator(p).run(_table(np.full(n_holds, u0), h))[:, columns]
        window_steps = slice(settle_holds * OUTPUTS_PER_HOLD, n_holds * OUTPUTS_PER_HOLD)
        t_end = (np.arange(n_holds * OUTPUTS_PER_HOLD) * h + h)[window_steps]
        U = _staircase_harmonic(starts[settle_holds:], hold, sine[settle_holds:], w, measure_periods * period)
        difference = excited[window_steps] - base[window_steps]
        motor.append(_harmonic(t_end, difference[:, 0], w) / U)
        cam.append(_harmonic(t_end, difference[:, 1], w) / U)
    return Response(np.asarray(f, dtype=float), np.array(motor), np.array(cam), float(u0), note)


__all__ = ["measured_response"]
