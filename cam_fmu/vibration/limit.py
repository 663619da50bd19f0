"""The machine's top speed for a residual tolerance: the smallest ratio r above which the residual stays within.

Undamped, |int_0^1 A(u) e^{i W u} du| <= int_0^1 |A| du, so R(r) <= int |A| / (2 pi r sqrt(1 - zeta^2)) (damped
too: |exp(lambda (1 - u))| <= 1): beyond r_bound = int |A| / (2 pi sqrt(1 - zeta^2) X) the residual is within X
at every r. Below it R is scanned on a grid of step ``step`` (R oscillates with a period of about 1 in r) and the
last crossing is located by bisection. The speed follows from r = t_r f_n, t_r = beta / omega for a rise over the
cam angle beta [rad] and a train of natural frequency f_n [Hz]: omega_max = beta f_n / r_limit.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from .spectral import check_zeta, residual

__all__ = ["Limit", "largest_failing_ratio", "top_speed_rpm"]


@dataclass(frozen=True)
class Limit:
    """r_limit: every r > r_limit keeps the residual within the tolerance (0: every r does); r_bound: the
    bound beyond which no scan is needed."""

    tolerance: float
    zeta: float
    r_limit: float
    r_bound: float


def _abs_area(law, points: int = 200001) -> float:
    u = np.linspace(0.0, 1.0, points)
    _, _, A, _ = law.evaluate(u)
    a = np.abs(A)
    return float(np.sum(0.5 * (a[1:] + a[:-1])) * (u[1] - u[0]))


def largest_failing_ratio(law, tolerance: float, zeta: float = 0.0, step: float = 0.002) -> Limit:
    """The smallest r_limit such that the residual / lift <= tolerance for every r > r_limit."""
    X = float(tolerance)
    if not (math.isfinite(X) and 0.0 < X < 1.0):
        raise ValueError(f"--limit {tolerance!r}: allowed a residual / lift in (0, 1)")
    z = check_zeta(zeta)
    r_bound = 1.02 * _abs_area(law) / (2.0 * math.pi * math.sqrt(1.0 - z * z) * X)
    r = np.arange(step, r_bound + step, step)
    R = np.concatenate([residual(law, chunk, z) for chunk in np.array_split(r, max(1, r.size // 20000))])
    over = np.nonzero(R > X)[0]
    if over.size == 0:
        return Limit(X, z, 0.0, r_bound)
    k = int(over[-1])
    lo, hi = float(r[k]), float(r[k + 1]) if k + 1 < r.size else r_bound
    for _ in range(60):
        mid = 0.5 * (lo + hi)
        if residual(law, mid, z)[0] > X:
            lo = mid
        else:
            hi = mid
    return Limit(X, z, hi, r_bound)


def top_speed_rpm(r_limit: float, rise_angle: float, train_hz: float) -> float:
    """The cam speed [1/min] at which a rise over ``rise_angle`` [rad] lasts r_limit natural periods of a train
    of ``train_hz`` [Hz]; inf for r_limit = 0."""
    if r_limit <= 0.0:
        return math.inf
    return rise_angle * train_hz / r_limit * 60.0 / (2.0 * math.pi)
