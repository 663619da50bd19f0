"""The harmonic-trapezoid law shaped against the residual vibration over a band of r (scipy.optimize).

Unknowns: the seven segment lengths L_1..L_7 >= 0 (sum 1; T_k = L_1 + ... + L_k) and the worst residual t.
Minimise t subject to

    R(r_j) <= t on a grid r_j over the band (``spectral.residual``, closed form),
    Amp <= Ca and Amm <= Ca,
    Amp pi / 2 <= Cj L_1, Amp pi / 2 <= Cj L_3, Amm pi / 2 <= Cj L_5, Amm pi / 2 <= Cj L_7

(|J| of a quarter sine or cosine of length L and amplitude c peaks at c pi / (2 L); written multiplied out, so
an empty ramp is an unbounded jerk, not a division by zero) by SLSQP from several starts (the modified sine,
the cycloidal, the modified trapezoid and the best law found so far), the epigraph form of the min-max. The
worst residual reported is the maximum over a grid ten times finer, refined by golden-section search.
Along a front of jerk bounds each solve also starts from the previous bound's law, which stays feasible, so the
front never gets worse as the bound grows.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..kinematics.characteristics import characteristics
from ..kinematics.motion_law import MotionLaw, golden_max
from ..kinematics.presets import PRESETS
from .spectral import check_ratios, residual

__all__ = ["Optimum", "worst_residual", "optimize_law", "pareto_front", "check_band", "MIN_CA",
           "DEFAULT_CA", "CLASSIC_STARTS"]

MIN_CA = 4.0                          # the family's least peak acceleration: constant acceleration's
DEFAULT_CA = 1.15 * 2.0 * math.pi     # 1.15 x the cycloidal's Ca
CLASSIC_STARTS = ("modified_sine", "cycloidal", "modified_trapezoid")
_GRID = 121
_MIN_PHASE = 1e-3                     # T3 >= and 1 - T4 >= this: the law needs both phases


@dataclass(frozen=True)
class Optimum:
    """A law found: its split points, the worst residual over the band, its Ca and Cj (None: unbounded)."""

    T: tuple[float, ...]
    worst: float
    r_worst: float
    Ca: float
    Cj: float | None
    max_ca: float
    max_cj: float | None


def check_band(r1: float, r2: float) -> tuple[float, float]:
    """(r1, r2) with 0 < r1 < r2 finite; ValueError naming --band otherwise."""
    if not (math.isfinite(r1) and math.isfinite(r2) and 0.0 < r1 < r2):
        raise ValueError(f"--band {r1:g}:{r2:g}: allowed R1:R2 with 0 < R1 < R2 (r = rise time / the train's "
                         "natural period, > 0)")
    return float(r1), float(r2)


def worst_residual(law, r1: float, r2: float, zeta: float = 0.0, points: int = 1201) -> tuple[float, float]:
    """(worst residual / lift over r in [r1, r2], the r where), by a grid refined by golden-section search."""
    r = np.linspace(r1, r2, points)
    R = residual(law, r, zeta)
    k = int(np.argmax(R))
    if 0 < k < points - 1:
        x, v = golden_max(lambda q: float(residual(law, q, zeta)[0]), float(r[k - 1]), float(r[k + 1]), 1e-10)
        if v >= R[k]:
            return v, x
    return float(R[k]), float(r[k])


def _lengths(T) -> np.ndarray:
    edges = np.concatenate(([0.0], np.asarray(T, dtype=float), [1.0]))
    return np.diff(edges)


def _law(x: np.ndarray) -> MotionLaw | None:
    L = np.clip(x[:6], 0.0, 1.0)
    T = np.minimum(np.cumsum(L), 1.0)
    try:
        return MotionLaw(tuple(float(t) for t in T))
    except ValueError:
        return None


def _solve(start_T, r_grid, zeta, max_ca, max_cj):
    from scipy.optimize import minimize

    half_pi = 0.5 * math.pi
    cache: dict = {}

    def evaluate(x):
        key = x[:6].tobytes()
        if key not in cache:
            law = _law(x)
            cache[key] = (law, residual(law, r_grid, zeta) if law is not None else None)
        return cache[key]

    def cons_residual(x):
        law, R = evaluate(x)
        return x[6] - R if law is not None else np.full(r_grid.size, -1.0)

    def cons_shape(x):
        law, _ = evaluate(x)
        L = np.clip(x[:6], 0.0, 1.0)
        L7 = 1.0 - L.sum()
        out = [L7, L[:3].sum() - _MIN_PHASE, L7 + L[4:].sum() - _MIN_PHASE]
        if law is None:
            return np.array(out + [-1.0] * (2 + (4 if max_cj is not None else 0)))
        out += [max_ca - law.Amp, max_ca - law.Amm]
        if max_cj is not None:
            out += [max_cj * L[0] - law.Amp * half_pi, max_cj * L[2] - law.Amp * half_pi,
                    max_cj * L[4] - law.Amm * half_pi, max_cj * L7 - law.Amm * half_pi]
        return np.array(out)

    L0 = _lengths(start_T)[:6]
    t0 = float(residual(MotionLaw(start_T), r_grid, zeta).max())
    res = minimize(lambda x: x[6], np.concatenate((L0, [t0])), method="SLSQP",
                   bounds=[(0.0, 1.0)] * 6 + [(0.0, None)],
                   constraints=[{"type": "ineq", "fun": cons_residual}, {"type": "ineq", "fun": cons_shape}],
                   options={"maxiter": 300, "ftol": 1e-12})
    law = _law(res.x)
    if law is None:
        return None
    feasible = bool(np.all(cons_shape(res.x) >= -1e-9))
    return law if feasible else None


def _optimum(law: MotionLaw, r1, r2, zeta, max_ca, max_cj) -> Optimum:
    c = characteristics(law)
    worst, where = worst_residual(law, r1, r2, zeta)
    return Optimum(T=law.T, worst=worst, r_worst=where, Ca=c.Am, Cj=c.Jm, max_ca=max_ca, max_cj=max_cj)


def _admissible(law: MotionLaw, max_ca: float, max_cj: float | None) -> bool:
    c = characteristics(law)
    if c.Am > max_ca * (1 + 1e-9):
        return False
    return max_cj is None or (c.Jm is not None and c.Jm <= max_cj * (1 + 1e-9))


def optimize_law(r1: float, r2: float, zeta: float = 0.0, max_ca: float = DEFAULT_CA,
                 max_cj: float | None = None, starts=(), grid: int = _GRID) -> Optimum:
    """The split points that minimise the worst residual over r in [r1, r2] with Ca <= max_ca and (unless None)
    Cj <= max_cj. ValueError when no law of the family meets the bounds."""
    r1, r2 = check_band(r1, r2)
    if not (math.isfinite(max_ca) and max_ca >= MIN_CA):
        raise ValueError(f"--max-ca {max_ca:g}: unreachable; no law of the family has a peak acceleration below "
                         f"{MIN_CA:g} (constant acceleration's; allowed >= {MIN_CA:g})")
    if max_cj is not None and not (math.isfinite(max_cj) and max_cj > 0.0):
        raise ValueError(f"--max-cj {max_cj:g}: allowed a peak jerk > 0")
    r_grid = check_ratios(np.linspace(r1, r2, grid))
    candidates = [MotionLaw(PRESETS[name]) for name in CLASSIC_STARTS] + [MotionLaw(T) for T in starts]
    found = [law for law in candidates if _admissible(law, max_ca, max_cj)]
    for start in candidates:
        law = _solve(start.T, r_grid, zeta, max_ca, max_cj)
        if law is not None and _admissible(law, max_ca, max_cj):
            found.append(law)
    if not found:
        raise ValueError(f"no harmonic-trapezoid law has Ca <= {max_ca:g}" + (
            f" and Cj <= {max_cj:g}" if max_cj is not None else "") + " (the bounds are unreachable together: "
            "raise --max-ca or --max-cj)")
    scored = [(worst_residual(law, r1, r2, zeta)[0], law) for law in found]
    best = min(scored, key=lambda p: p[0])[1]
    return _optimum(best, r1, r2, zeta, max_ca, max_cj)


def pareto_front(r1: float, r2: float, jerk_bounds, zeta: float = 0.0, max_ca: float = DEFAULT_CA,
                 ) -> list[Optimum]:
    """optimize_law at each jerk bound (increasing; None last: unbounded), each warm-started from the last law
    found; bounds no law meets are left out."""
    out: list[Optimum] = []
    bounds = sorted((b for b in jerk_bounds if b is not None)) + [b for b in jerk_bounds if b is None]
    for bound in bounds:
        starts = [out[-1].T] if out else []
        try:
            out.append(optimize_law(r1, r2, zeta, max_ca, bound, starts))
        except ValueError:
            continue
    return out
