"""Frequency response of the drive from the motor voltage u to the rotor's and the cam's speed: the theory.

Two operating points (docs/control.md section 5, docs/model.md section 12.3):

- **a frozen cam angle** theta0: the drive held at rest there by the voltage u0 that balances
  gravity, without shaft and guide friction and without backlash (Coulomb friction and a gap
  have no small-signal linearisation at rest; the response says it switched them off);
- **a mean speed**: the drive turning under a constant u0 (its scene's voltage); the response
  is the first harmonic at the excitation frequency, averaged over the turns the window spans.

``experiments.frequency.measured_response`` measures the response on the C engine.

``analytic_response`` is the linearised two-mass system at the frozen angle (docs/model.md
12.3) as a state-space model, H(j w) = C (j w I - A)^-1 B, evaluated with numpy.
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any, Mapping, Sequence

import numpy as np

from ..physics.drive import DriveModel

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
    model = DriveModel(p)
    if abs(model.F_gx) <= 1e-12 * p.get("G", 1.0) and model.F_gx != 0.0:
        # a horizontal mounting's gravity along X is sin(pi) G = 1.2e-16 G of rounding: held by a voltage of
        # 1e-15 V, the frictionless cam would crawl at rest and its stops chatter; it is no load at all
        p["gravity"] = False
        model = DriveModel(p)
    _, s1, s2, _ = model.program.derivatives(theta0)
    k_g = -model.F_gx * s2
    if k_g < -1e-12:  # N m/rad: a rounding remainder of a horizontal mounting (F_gx ~ 1e-16 G) is no stiffness
        raise ValueError(f"theta0 = {theta0!r} rad: gravity's stiffness there is k_g = -F_gx s'' = {k_g:.4g} N m/rad "
                         "< 0, the cam would fall away from a standstill (choose an angle where k_g >= 0, or "
                         "another mounting)")
    u0 = model.R * (-model.F_gx * s1) / model.c_m + 0.0  # + 0.0: no -0 V in a report
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


__all__ = ["FROZEN_OFF", "Response", "analytic_response", "frozen_parameters", "linear_model", "settle_time"]
