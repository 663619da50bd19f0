"""Frequency response measured on the C engine by small-signal simulation (control.frequency has the theory:
the operating points, the linearised drive and its analytic response; docs/control.md section 5).

``measured_response`` runs the C engine (DriveSimulator.run) with u = u0 + a sin(2 pi f t), held
over HOLDS_PER_PERIOD steps per period, lets it settle for the longer of SETTLE_PERIODS periods and
SETTLE_TIME_CONSTANTS time constants of the slowest pole of the linear model (one communication step
per held value, in chunks, not kept), splits each held value of the measured periods into
OUTPUTS_PER_HOLD communication steps, and fits a + c cos + d sin to the difference of the
speeds with and without the sine over MEASURE_PERIODS periods (at a mean speed: at least two
turns). The input's first harmonic is that of the staircase actually applied (exact), so the
hold's half-step delay is not mistaken for the drive's. The amplitude (default 1 mV) must keep
the response linear: the cam's angle excursion a |H_cam| / (2 pi f) small against the profile's
detail (at 1 mV and 1 Hz on the shipped compliant scene, 6e-4 rad). The work is bounded before
anything runs (OperatingPoint.reachable, MAX_HOLDS, MAX_INTERNAL_STEPS): a frequency out of reach
is refused with the range the operating point reaches.
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any, Callable, Mapping, Sequence

import numpy as np

from ..control.frequency import SETTLE_TIME_CONSTANTS, Response, frozen_parameters, settle_time
from ..control.kind_view import kind_view
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
# The work of one run (each frequency runs twice), bounded before anything is allocated: at most MAX_HOLDS held
# input values (64 per period, over the settling and the measurement; about 4 s of engine time each way on this
# machine) and at most MAX_INTERNAL_STEPS internal steps of h_max (the simulated time / h_max, a low frequency's
# cost). The settling runs in chunks of CHUNK_HOLDS held values, one communication step each, and is discarded:
# memory stays at a chunk plus the measured periods whatever the frequency.
MAX_HOLDS = 4_000_000
MAX_INTERNAL_STEPS = 10_000_000
CHUNK_HOLDS = 1 << 16


@dataclass(frozen=True)
class OperatingPoint:
    """What a measurement around one operating point needs: the engine's parameters, u0 [V], the settling time
    [s], the measurement window's floor [s] (two turns while turning), a note saying what it is and, while
    turning, the cam's turning frequency f_turn [Hz] (turns per second; None at a frozen angle)."""

    params: dict
    u0: float
    settle: float
    window: float
    note: str
    f_turn: float | None = None

    def holds(self, f: float) -> tuple[int, int]:
        """(held values before the measurement, periods measured) at f [Hz] (the settling rule)."""
        return (HOLDS_PER_PERIOD * max(SETTLE_PERIODS, math.ceil(self.settle * f)),
                max(MEASURE_PERIODS, math.ceil(self.window * f)))

    def span(self, f: float) -> float:
        """The measured window [s] at f [Hz]: the periods of the fit (the settling rule)."""
        return self.holds(f)[1] / f

    def work(self, f: float) -> tuple[int, float]:
        """(held values of one run, the engine's internal steps at least: simulated time / h_max) at f [Hz]."""
        settle_holds, periods = self.holds(f)
        n = settle_holds + HOLDS_PER_PERIOD * periods
        return n, n / (HOLDS_PER_PERIOD * f) / float(self.params.get("h_max", _default("h_max")))

    def reachable(self) -> tuple[float, float]:
        """(lowest, highest) frequency [Hz] whose runs stay within MAX_INTERNAL_STEPS and MAX_HOLDS."""
        def fits(f: float, which: int) -> bool:
            n, internal = self.work(f)
            return internal <= MAX_INTERNAL_STEPS if which == 0 else n <= MAX_HOLDS

        lo, hi = 1e-12, 1e12  # bisection on log f: the internal steps fall with f, the held values grow
        a, b = lo, hi
        for _ in range(200):
            m = math.sqrt(a * b)
            a, b = (a, m) if fits(m, 0) else (m, b)
        f_lo = b
        a, b = lo, hi
        for _ in range(200):
            m = math.sqrt(a * b)
            a, b = (m, b) if fits(m, 1) else (a, m)
        return f_lo, a

    def check(self, f: Sequence[float], names: tuple[str, str] = ("frequency", "frequency")) -> None:
        """ValueError, before anything runs, when a frequency [Hz] is out of reach: it names the reachable range
        and why (``names``: what to call the lowest and the highest frequency in the message)."""
        f_lo, f_hi = self.reachable()
        h_max = float(self.params.get("h_max", _default("h_max")))
        why = (f"the drive settles over {self.settle:.4g} s before each measurement, {HOLDS_PER_PERIOD} held inputs "
               f"per period; one run holds at most {MAX_HOLDS:,} inputs and takes at most {MAX_INTERNAL_STEPS:,} "
               f"internal steps of h_max = {h_max:g} s")
        if f_lo > f_hi:
            raise ValueError(f"no frequency is reachable at this operating point ({why}; a larger h_max shortens the "
                             "work)")
        for name, fk, bad in ((names[0], min(f), min(f) < f_lo), (names[1], max(f), max(f) > f_hi)):
            if bad:
                raise ValueError(f"{name} {fk:g} Hz is out of reach at this operating point: reachable {f_lo:.4g} to "
                                 f"{f_hi:.4g} Hz ({why})")


def _default(name: str) -> float:
    from ..physics.parameters import BY_NAME

    return float(BY_NAME[name].default)


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


def _table(u: np.ndarray, h: float, first: int = 0, per_hold: int = OUTPUTS_PER_HOLD) -> np.ndarray:
    """The engine's input table: every held value of u over ``per_hold`` communication steps of h [s], the first
    at step number ``first`` (times k h from 0)."""
    n = len(u) * per_hold
    return np.column_stack([(first + np.arange(n)) * h, np.full(n, h), np.repeat(u, per_hold), np.ones(n),
                            np.zeros(n)])


def operating_point(params: Mapping[str, Any] | None, theta0: float | None = None,
                    u0: float | None = None) -> OperatingPoint:
    """The operating point: frozen at ``theta0`` [rad], else turning under ``u0`` [V] (module docstring). A speed
    drive is refused: its cam speed is the input omega_ref, u plays no part."""
    if dict(params or {}).get("drive", "voltage") != "voltage":  # the speed drive (the parameter's other choice)
        raise ValueError("drive = 'speed': the cam's speed is the input omega_ref and the voltage u plays no part, so "
                         "there is no response from u to measure; a speed drive's response is the voltage (and current) "
                         "it needs for a given omega_ref, its outputs 'voltage' and 'i' (cam-fmu simulate); use "
                         "drive = 'voltage' for a frequency response")
    if theta0 is not None:
        p, u0 = frozen_parameters(params, theta0)
        return OperatingPoint(p, u0, settle_time(params, theta0), 0.0, (
            f"frozen at theta0 = {theta0:.6g} rad, held by u0 = {u0:.6g} V; shaft and guide friction and backlash off"))
    if u0 is None or not math.isfinite(u0):
        raise ValueError("give the operating point: theta0 (a frozen angle) or a finite u0 [V] (a mean speed)")
    p = dict(params or {})
    view = kind_view(p)
    angles = np.linspace(0.0, 2.0 * math.pi, 361)
    if view is None:
        model = DriveModel(p)
        carried = model.m + (model.train.m_end if model.train.active else 0.0)  # a train's end mass at low frequency
        J_heavy = max(model.J_0 + carried * model.program.derivatives(t)[1] ** 2
                      for t in angles) + (model.J_m if model.compliant else 0.0)
    else:  # another follower type: its J(theta) (control.kind_view); the engine runs it on a rigid shaft
        model = view.model
        J_heavy = max(view.low_frequency_inertia(float(t)) for t in angles) + (view.J_m if view.compliant else 0.0)
    settle = SETTLE_TIME_CONSTANTS * model.R * J_heavy / (model.c_e * model.c_m)  # the slowest mechanical pole
    h = 1e-3
    run = DriveSimulator(p).run(_table(np.full(max(1, math.ceil(settle / h / OUTPUTS_PER_HOLD)), u0), h))
    theta = run[:, OUTPUT_NAMES.index("theta")]
    half = len(theta) // 2
    turn_rate = abs(theta[-1] - theta[half]) / ((len(theta) - half) * h) / (2.0 * math.pi)  # turns per second
    if not turn_rate > 1e-3:
        raise ValueError(f"u0 = {u0!r} V: the cam does not turn (it comes to rest); give a frozen angle instead")
    turn_rate = _turn_rate(theta[half:], h) or turn_rate
    return OperatingPoint(p, u0, settle, 2.0 / turn_rate, f"turning under u0 = {u0:.6g} V at "
                          f"{60.0 * turn_rate:.6g} 1/min, {turn_rate:.6g} turns/s (the first harmonic at f, averaged "
                          "over at least two turns)", turn_rate)


def _turn_rate(theta: np.ndarray, h: float) -> float | None:
    """Turns per second [1/s] between the first and the last whole turn completed in ``theta`` [rad], sampled
    every h [s] (each crossing of a multiple of 2 pi interpolated linearly): exact for a periodic turning, while
    theta's mean slope over a part of a turn is off by the speed's ripple. None under two crossings."""
    turns = np.floor(theta / (2.0 * math.pi))
    k = np.nonzero(np.diff(turns))[0]
    if len(k) < 2:
        return None
    level = 2.0 * math.pi * np.maximum(turns[k], turns[k + 1])
    t = (k + (level - theta[k]) / (theta[k + 1] - theta[k])) * h
    return (len(k) - 1) / abs(t[-1] - t[0])


def _measured_run(p: Mapping[str, Any], u: np.ndarray, hold: float, settle_holds: int) -> np.ndarray:
    """The engine's outputs over the measured holds of the staircase ``u`` (one value per hold of ``hold`` [s]):
    the settling holds run first in chunks, one communication step each, their outputs dropped; the measured
    holds run OUTPUTS_PER_HOLD communication steps each."""
    sim = DriveSimulator(p)
    for first in range(0, settle_holds, CHUNK_HOLDS):
        sim.run(_table(u[first:min(first + CHUNK_HOLDS, settle_holds)], hold, first, per_hold=1))
    h = hold / OUTPUTS_PER_HOLD
    return sim.run(_table(u[settle_holds:], h, settle_holds * OUTPUTS_PER_HOLD))


def measured_response(params: Mapping[str, Any] | None, f: Sequence[float], theta0: float | None = None,
                      u0: float | None = None, amplitude: float = 1e-3, point: OperatingPoint | None = None,
                      progress: Callable[[int, int], None] | None = None) -> Response:
    """H(j 2 pi f) measured on the C engine by small-signal simulation (module docstring).

    ``theta0`` [rad]: the frozen-angle operating point (friction and backlash off, u0 from gravity); else the
    drive turning under ``u0`` [V] with everything its parameters model (or ``point``, from operating_point).
    ``amplitude`` [V] of the sine. Each frequency runs the drive twice from the same start, with and without the
    sine, and fits the difference: the operating point's own motion (the cam's turning, a settling transient)
    cancels exactly. A frequency out of reach (OperatingPoint.reachable) is refused before anything runs.
    ``progress(done, total)``: called before the first frequency and after each (e.g. progress.ProgressBar)."""
    if not (math.isfinite(amplitude) and amplitude > 0.0):
        raise ValueError(f"amplitude = {amplitude!r} V: allowed > 0")
    f = np.asarray(f, dtype=float)
    for fk in f:
        if not (math.isfinite(fk) and fk > 0.0):
            raise ValueError(f"frequency {fk!r} Hz: allowed > 0")
    point = point or operating_point(params, theta0, u0)
    point.check(f)
    p, u0 = point.params, point.u0
    columns = [OUTPUT_NAMES.index("omega_m"), OUTPUT_NAMES.index("omega")]
    motor, cam = [], []
    if progress is not None:
        progress(0, len(f))
    for k, fk in enumerate(f):
        period = 1.0 / fk
        hold = period / HOLDS_PER_PERIOD
        h = hold / OUTPUTS_PER_HOLD
        settle_holds, measure_periods = point.holds(fk)
        n_holds = settle_holds + HOLDS_PER_PERIOD * measure_periods
        starts = np.arange(n_holds) * hold
        w = 2.0 * math.pi * fk
        sine = amplitude * np.sin(w * (starts + 0.5 * hold))  # the sine sampled mid-hold
        excited = _measured_run(p, u0 + sine, hold, settle_holds)[:, columns]
        base = _measured_run(p, np.full(n_holds, u0), hold, settle_holds)[:, columns]
        t_end = (settle_holds * OUTPUTS_PER_HOLD + np.arange(len(excited)) + 1) * h
        U = _staircase_harmonic(starts[settle_holds:], hold, sine[settle_holds:], w, measure_periods * period)
        difference = excited - base
        motor.append(_harmonic(t_end, difference[:, 0], w) / U)
        cam.append(_harmonic(t_end, difference[:, 1], w) / U)
        if progress is not None:
            progress(k + 1, len(f))
    return Response(f, np.array(motor), np.array(cam), float(u0), point.note)


__all__ = ["OperatingPoint", "measured_response", "operating_point"]
