"""The largest fixed step that resolves the follower train's oscillation (issue 41, item 3).

The train in the drive (an end mass ``m_end`` [kg] on a spring ``k_train`` [N/m] and damper ``d_train`` [N.s/m]
behind a follower whose motion the cam imposes) rings as y' = lambda y with

    lambda = -zeta omega_n +/- i omega_n sqrt(1 - zeta^2),   omega_n = sqrt(k_train / m_end),
    zeta = d_train / (2 sqrt(k_train m_end))   (zeta >= 1: two real roots).

A one-step method multiplies that mode by its stability polynomial R(h lambda) per step (euler: 1 + z; rk4: the
degree-4 Taylor polynomial of e^z). Over one natural period T = 2 pi / omega_n, N = T / h steps, the run's relative
error on the mode is |R(z)^N - e^(N z)| / |e^(N z)|. A step resolves the train when that error is at most ``tol``;
``largest_step`` finds the largest such h by bisection (the error grows with h on the interval searched), and
``check_step`` refuses a step above it with a message naming ``k_train``, the step and the step that would do.
rk45 chooses its own step (no limit); etdrk4 integrates the rigid drive's pole only and is refused with a train
as it is with a compliant shaft. Imports ``math``, ``cmath`` and the solver registry.
"""
from __future__ import annotations

import cmath
import math

from .solvers import SOLVERS

__all__ = ["train_rates", "amplification", "period_error", "largest_step", "check_step", "TOL"]

TOL = 1e-3  # relative error on the train's ringing over one natural period a fixed step may make


def train_rates(k_train: float, d_train: float, m_end: float) -> tuple[complex, float]:
    """The train's eigenvalue lambda [1/s] (upper half plane; the slower root where zeta >= 1) and omega_n [rad/s]."""
    if not (k_train > 0 and math.isfinite(k_train)):
        raise ValueError(f"parameter 'k_train' = {k_train!r} N/m: allowed > 0 here (0 is the rigid train)")
    if not (m_end > 0 and math.isfinite(m_end)):
        raise ValueError(f"parameter 'm_end' = {m_end!r} kg: allowed > 0 with k_train > 0")
    if not (d_train >= 0 and math.isfinite(d_train)):
        raise ValueError(f"parameter 'd_train' = {d_train!r} N.s/m: allowed >= 0")
    wn = math.sqrt(k_train / m_end)
    zeta = d_train / (2.0 * math.sqrt(k_train * m_end))
    if zeta < 1.0:
        return complex(-zeta * wn, wn * math.sqrt(1.0 - zeta * zeta)), wn
    return complex(-wn * (zeta - math.sqrt(zeta * zeta - 1.0)), 0.0), wn


def amplification(solver: str, z: complex) -> complex:
    """R(z): what one step of ``solver`` multiplies the linear mode e^(lambda t) by, z = h lambda."""
    order = SOLVERS[solver].taylor_order
    if order == 0:
        fixed = ", ".join(repr(s.name) for s in SOLVERS.values() if s.taylor_order)
        raise ValueError(f"solver {solver!r}: a polynomial step applies to {fixed}")
    term, total = 1.0 + 0j, 1.0 + 0j
    for k in range(1, order + 1):
        term *= z / k
        total += term
    return total


def period_error(solver: str, lam: complex, wn: float, h: float) -> float:
    """Relative error on the mode lambda after one natural period 2 pi / wn in steps of h [s] (N = T/h, real)."""
    n = 2.0 * math.pi / (wn * h)
    z = h * lam
    r = amplification(solver, z)
    if r == 0:
        return 1.0
    exact = cmath.exp(n * z)
    return abs(cmath.exp(n * cmath.log(r)) - exact) / abs(exact)


def largest_step(solver: str, k_train: float, d_train: float, m_end: float, tol: float = TOL) -> float:
    """The largest step [s] at which ``solver`` keeps the train's ringing within ``tol`` over one natural period."""
    lam, wn = train_rates(k_train, d_train, m_end)
    lo, hi = 0.0, 2.0 * math.pi / wn  # one step per period never resolves it
    if period_error(solver, lam, wn, hi) <= tol:
        return hi
    for _ in range(200):
        mid = 0.5 * (lo + hi)
        if mid == lo or mid == hi:
            break
        if period_error(solver, lam, wn, mid) <= tol:
            lo = mid
        else:
            hi = mid
    return lo


def check_step(solver: str, step: float, k_train: float, d_train: float, m_end: float, tol: float = TOL) -> None:
    """Raise ValueError where a fixed ``step`` [s] of ``solver`` cannot resolve the train (k_train > 0)."""
    if k_train == 0.0 or SOLVERS[solver].adaptive:
        return
    if SOLVERS[solver].taylor_order == 0:  # etdrk4: its exponential is the rigid drive's electrical pole
        raise ValueError(f"parameter 'k_train' = {k_train!r} N/m: solver {solver!r} integrates the rigid drive's "
                         "electrical pole; allowed with it: k_train = 0 (use solver 'rk45')")
    h_max = largest_step(solver, k_train, d_train, m_end, tol)
    if step > h_max:
        period = 2.0 * math.pi * math.sqrt(m_end / k_train)
        raise ValueError(f"parameter 'k_train' = {k_train!r} N/m: the train's natural period {period:.4g} s is too "
                         f"short for solver {solver!r} at step {step:.4g} s (error over a period above {tol:g}); "
                         f"allowed: step <= {h_max:.4g} s, a smaller k_train, or solver 'rk45'")
