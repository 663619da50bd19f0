"""Frequency response of the drive from the motor voltage u to the rotor's and the cam's speed: the theory.

Two operating points (docs/control.md section 5, docs/model.md section 12.3):

- **a frozen cam angle** theta0: the drive held at rest there by the voltage u0 that balances
  gravity, without shaft and guide friction and without backlash (Coulomb friction and a gap
  have no small-signal linearisation at rest; the response says it switched them off);
- **a mean speed**: the drive turning under a constant u0 (its scene's voltage); the response
  is the first harmonic at the excitation frequency, averaged over the turns the window spans.

``experiments.frequency.measured_response`` measures the response on the C engine.

``analytic_response`` is the linearised two-mass system at the frozen angle (docs/model.md
12.3) as a state-space model, H(j w) = C (j w I - A)^-1 B, evaluated with numpy. Every follower type: another
kind's J(theta0), holding voltage and gravity's stiffness come from its potential (control.kind_view, docs/model.md
16.2).
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any, Mapping, Sequence

import numpy as np

from ..physics.drive import DriveModel
from ..physics.train import Train
from .kind_view import KindView, kind_view

SETTLE_TIME_CONSTANTS = 8.0  # time constants of the slowest pole of the linear model, at least
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
    view = kind_view(p)
    if view is not None:
        return _kind_frozen(p, view, theta0)
    model = DriveModel(p)
    if abs(model.F_gx) <= 1e-12 * p.get("G", 1.0) and model.F_gx != 0.0:
        # a horizontal mounting's gravity along X is sin(pi) G = 1.2e-16 G of rounding: held by a voltage of
        # 1e-15 V, the frictionless cam would crawl at rest and its stops chatter; it is no load at all
        p["gravity"] = False
        model = DriveModel(p)
    _, s1, s2, _ = model.program.derivatives(theta0)
    F_x = model.F_gx + model.train_weight()  # N: gravity along X on the follower, and on a train's end mass
    k_g = -F_x * s2
    if k_g < -1e-12:  # N m/rad: a rounding remainder of a horizontal mounting (F_gx ~ 1e-16 G) is no stiffness
        raise ValueError(f"theta0 = {theta0!r} rad: gravity's stiffness there is k_g = -F_x s'' = {k_g:.4g} N m/rad "
                         "< 0, the cam would fall away from a standstill (choose an angle where k_g >= 0, or "
                         "another mounting)")
    u0 = model.R * (-F_x * s1) / model.c_m + 0.0  # + 0.0: no -0 V in a report
    if model.L > 0.0:
        p["i0"] = u0 / model.R
    return p, u0


def _kind_frozen(p: dict[str, Any], view: KindView, theta0: float) -> tuple[dict[str, Any], float]:
    """frozen_parameters for a follower of another kind (control.kind_view): gravity's stiffness k_g = d2V/dtheta2
    and the holding voltage u0 = R M_g / c_m from the kind's potential."""
    model = view.model
    k_g = view.gravity_stiffness(theta0)
    if k_g < -1e-12:
        raise ValueError(f"theta0 = {theta0!r} rad: gravity's stiffness there is k_g = d2V/dtheta2 = {k_g:.4g} N m/rad "
                         f"< 0 (follower_type {model.kind.follower_type!r}), the cam would fall away from a standstill "
                         "(choose an angle where k_g >= 0, or another mounting)")
    u0 = model.R * view.gravity_torque(theta0) / model.c_m + 0.0  # + 0.0: no -0 V in a report
    if model.L > 0.0:
        p["i0"] = u0 / model.R
    return p, u0


def _with_train(train: Train, s1: float, J_c: float, A: list, C: list) -> tuple[list, list]:
    """A and C with a train's end mass (docs/model.md 14.6) appended as two states, its deviation from the static
    deflection and its velocity, in the law's lift units along s (an arm's torsional train scaled, control.kind_view):
    dF = k_train (s' dtheta - x_e) + d_train (s' omega - v_e) pulls the cam (row 1, its speed) by -s' dF / J_c and
    drives the end mass, m_end v_e' = dF."""
    k, d, m_e = train.k_train, train.d_train, train.m_end
    n = len(A)
    A = [row + [0.0, 0.0] for row in A] + [[0.0] * (n + 2) for _ in range(2)]
    A[1][0] -= s1 * k * s1 / J_c
    A[1][1] -= s1 * d * s1 / J_c
    A[1][n], A[1][n + 1] = s1 * k / J_c, s1 * d / J_c
    A[n][n + 1] = 1.0
    A[n + 1][0], A[n + 1][1], A[n + 1][n], A[n + 1][n + 1] = k * s1 / m_e, d * s1 / m_e, -k / m_e, -d / m_e
    return A, [row + [0.0, 0.0] for row in C]


def linear_model(params: Mapping[str, Any] | None, theta0: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(A, B, C) of the drive linearised at rest at theta0 [rad] without friction (docs/model.md 12.3): states
    (theta - theta0, omega, phi, omega_m[, i][, x_e, v_e]); input u [V]; outputs (omega_m, omega) [rad/s]. A rigid
    shaft is the one-mass limit: states (theta - theta0, omega[, i][, x_e, v_e]), both outputs omega. A follower
    train (k_train > 0, k_train_arm > 0 on an arm) adds its end mass's deviation and velocity (in the law's lift units
    along s), and its weight to gravity's stiffness."""
    p = dict(params or {}, **FROZEN_OFF)
    view = kind_view(p)
    if view is None:
        model = DriveModel(p)
        _, s1, s2, _ = model.program.derivatives(theta0)
        J_c = model.J_0 + model.m * s1 * s1
        k_g = -(model.F_gx + model.train_weight()) * s2
        compliant, k, d, J_m = model.compliant, model.k_shaft, model.d_shaft, model.J_m
        train = model.train if model.train.active else None
    else:  # another follower type: its J_c(theta0), gravity's stiffness and its train (control.kind_view)
        model = view.model
        J_c, k_g = view.cam_side(theta0), view.gravity_stiffness(theta0)
        s1, train = model.program.derivatives(theta0)[1], view.train
        compliant, k, d, J_m = view.compliant, view.k_shaft, view.d_shaft, view.J_m
    R, L, c_e, c_m = model.R, model.L, model.c_e, model.c_m
    damping = 0.0 if L > 0.0 else c_m * c_e / R  # L = 0: the back-EMF's torque -c_m c_e omega_m / R
    gain = 0.0 if L > 0.0 else c_m / R  # L = 0: the motor's torque per volt
    if compliant:
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
        A[motor_row][n] = c_m / (J_m if compliant else J_c)
        A[n][speed] = -c_e / L
        A[n][n] = -R / L
        B = B + [1.0 / L]
        C = [row + [0.0] for row in C]
    if train is not None:
        A, C = _with_train(train, s1, J_c, A, C)
        B = B + [0.0, 0.0]
    return np.array(A), np.array(B), np.array(C)


def analytic_response(params: Mapping[str, Any] | None, theta0: float, f: Sequence[float]) -> Response:
    """H(j 2 pi f) of the linearised drive at the frozen angle theta0 [rad] (docs/model.md 12.3)."""
    A, B, C = linear_model(params, theta0)
    f = np.asarray(f, dtype=float)
    eye = np.eye(len(A))
    H = np.array([C @ np.linalg.solve(2j * math.pi * fk * eye - A, B) for fk in f])
    _, u0 = frozen_parameters(params, theta0)
    return Response(f, H[:, 0], H[:, 1], u0, f"linearised at rest at theta0 = {theta0:.6g} rad")


# The extrema of |H| that count (resonances: local maxima; anti-resonances: local minima of a sampled |H|): those
# whose prominence (scipy.signal.find_peaks, on ln |H|) is at least EXTREMUM_PROMINENCE, 1 % of |H|: a flat stretch
# of a finely sampled curve has no extremum to report. Each is refined by golden-section search on ln f inside
# the two grid intervals around its sample, until the bracket is narrower than EXTREMUM_TOLERANCE (relative).
EXTREMUM_PROMINENCE = 0.01
EXTREMUM_TOLERANCE = 1e-3
_GOLDEN = (math.sqrt(5.0) - 1.0) / 2.0


@dataclass
class Extremum:
    """A resonance (local maximum of |H|) or anti-resonance (local minimum) of one output's response."""

    output: str  # 'motor' (omega_m) or 'cam' (omega)
    kind: str  # 'resonance' or 'anti-resonance'
    f: float  # Hz, within ``tolerance`` (relative) of the extremum of the curve searched
    gain: float  # |H| there, (rad/s)/V
    tolerance: float  # the bracket's relative width at the end of the search


def grid_extrema(gain: Sequence[float], prominence: float = EXTREMUM_PROMINENCE) -> list[tuple[int, str]]:
    """(index, kind) of the interior local extrema of a sampled |H| with a prominence of at least ``prominence``
    (relative), in grid order; an end of the grid is no extremum."""
    from scipy.signal import find_peaks

    level = np.log(np.maximum(np.asarray(gain, dtype=float), np.finfo(float).tiny))
    depth = math.log1p(prominence)
    found = [(int(k), "resonance") for k in find_peaks(level, prominence=depth)[0]]
    found += [(int(k), "anti-resonance") for k in find_peaks(-level, prominence=depth)[0]]
    return sorted(found)


def refine_extremum(gain_at, lo: float, hi: float, kind: str,
                    tolerance: float = EXTREMUM_TOLERANCE) -> tuple[float, float, float]:
    """(f [Hz], |H| there, relative width of the final bracket) of the extremum of ``gain_at(f)`` between lo and hi
    [Hz]: golden-section search on ln f, to a bracket hi/lo - 1 below ``tolerance``; the best point evaluated."""
    sign = -1.0 if kind == "resonance" else 1.0  # minimise sign * ln |H|
    a, b = math.log(lo), math.log(hi)
    seen: dict[float, float] = {}

    def cost(x: float) -> float:
        if x not in seen:
            seen[x] = float(gain_at(math.exp(x)))
        return sign * math.log(max(seen[x], np.finfo(float).tiny))

    c, d = b - _GOLDEN * (b - a), a + _GOLDEN * (b - a)
    while math.expm1(b - a) > tolerance:
        if cost(c) < cost(d):
            b, d = d, c
            c = b - _GOLDEN * (b - a)
        else:
            a, c = c, d
            d = a + _GOLDEN * (b - a)
    x = min(seen, key=cost) if seen else 0.5 * (a + b)
    if not seen:
        seen[x] = float(gain_at(math.exp(x)))
    return math.exp(x), seen[x], math.expm1(b - a)


def locate_extrema(response: Response, response_at, tolerance: float = EXTREMUM_TOLERANCE,
                   progress=None) -> list[Extremum]:
    """Every resonance and anti-resonance of the motor's and the cam's |H| sampled in ``response``, each refined by
    ``response_at(f) -> Response`` at single frequencies [Hz] (grid_extrema, refine_extremum). ``progress(done,
    total)``: called before the first search and after each (one search an extremum)."""
    f = np.asarray(response.f, dtype=float)
    todo = [(output, k, kind) for output in ("motor", "cam")
            for k, kind in grid_extrema(np.abs(getattr(response, output)))]
    found = []
    if progress is not None and todo:
        progress(0, len(todo))
    for output, k, kind in todo:
        def gain_at(fk: float, output: str = output) -> float:
            return abs(getattr(response_at(fk), output)[0])

        fk, gk, width = refine_extremum(gain_at, f[k - 1], f[k + 1], kind, tolerance)
        found.append(Extremum(output, kind, fk, gk, width))
        if progress is not None:
            progress(len(found), len(todo))
    return found


# What an extremum of a turning drive's response is (docs/control.md section 5). The turning is a periodic motion
# whose phase nothing holds (shifted in time it is a motion of the drive too), and its load repeats every turn: a
# sine at k f_turn, in step with the load's k-th harmonic, does net work on the turning every turn and drives its
# phase over the whole settling; the speed difference the measurement fits is then the turning's own speed
# shifted, whose harmonic k sits at f (measured: 97 % of the 168 (rad/s)/V at 6 f_turn on the paper drive
# remains when the sine stops as the window opens). The fit over a window of W seconds sees a harmonic within
# the half width of its main lobe, 1 / (2 W): a peak there is the turning's harmonic k, not a resonance. A mechanical
# resonance of a compliant shaft lies in the band its two-mass resonance f_r(theta) (anti-resonance f_a(theta))
# spans over a turn (control.reflect), widened by SHAFT_BAND_MARGIN for the damping and the turning's averaging;
# it is checked first. Anything else is neither: a maximum or minimum of the fit between the harmonics, no
# resonance of the drive.
SHAFT_BAND_MARGIN = 0.05
CAUSES = ("shaft", "turning harmonic", "neither")


def turning_cause(f: float, kind: str, f_turn: float, span: float,
                  bands: Mapping[str, Sequence[float] | None] | None = None) -> tuple[str, int | None]:
    """(cause, k) of a turning drive's extremum at f [Hz] of ``kind`` ('resonance': a local maximum of |H|,
    'anti-resonance': a minimum), measured over ``span`` [s]: ('shaft', None) inside the compliant shaft's band of
    that kind (``bands``: {'resonance': (f_r_min, f_r_max), 'anti-resonance': (f_a_min, f_a_max)} [Hz] for the
    rotor's speed; the cam's speed has no anti-resonance there, its 'anti-resonance' None; None for a rigid
    shaft), else ('turning harmonic', k) for a maximum within 1 / (2 span) of k f_turn [Hz], else ('neither',
    None). See CAUSES' comment."""
    if not (f_turn > 0.0 and math.isfinite(f_turn)) or not (span > 0.0 and math.isfinite(span)):
        raise ValueError(f"f_turn = {f_turn!r} Hz, span = {span!r} s: allowed > 0")
    band = None if bands is None else bands.get(kind)
    if band is not None and band[0] * (1.0 - SHAFT_BAND_MARGIN) <= f <= band[1] * (1.0 + SHAFT_BAND_MARGIN):
        return "shaft", None
    k = round(f / f_turn)
    if kind == "resonance" and k >= 1 and abs(f - k * f_turn) <= 0.5 / span:
        return "turning harmonic", int(k)
    return "neither", None


def settle_time(params: Mapping[str, Any] | None, theta0: float) -> float:
    """SETTLE_TIME_CONSTANTS time constants [s] of the slowest decaying pole of the linear model at theta0."""
    rates = [-ev.real for ev in np.linalg.eigvals(linear_model(params, theta0)[0]) if ev.real < -1e-9]
    return SETTLE_TIME_CONSTANTS / min(rates) if rates else 0.0


__all__ = ["CAUSES", "SHAFT_BAND_MARGIN", "turning_cause", "EXTREMUM_PROMINENCE", "EXTREMUM_TOLERANCE", "Extremum", "FROZEN_OFF", "Response", "analytic_response",
           "frozen_parameters", "grid_extrema", "linear_model", "locate_extrema", "refine_extremum", "settle_time"]
