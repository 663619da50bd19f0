"""The follower train integrated over a rise and the following dwell (scipy's solve_ivp, tight tolerances).

The end mass x [lift] is pulled by the spring and damper from the follower y = S(u) (u = t / t_r, lengths in h,
the end mass as the unit of mass):

    x'' = W^2 (y - x) + 2 zeta W (y' - x'),    W = 2 pi r,

from rest at x = 0. Two more states carry the energy balance: the work the follower does on the train,
P_in = F y' with F = W^2 (y - x) + 2 zeta W (y' - x'), and the damper's loss, P_d = 2 zeta W (y' - x')^2, so that

    x'^2 / 2 + W^2 (y - x)^2 / 2 + E_d = W_in        at every u.

The rise is integrated piece by piece between the law's split points (the acceleration may jump there), then
``dwell`` natural periods of the dwell; the residual is the free ringing's amplitude at the dwell's start,
R = sqrt(e^2 + ((e' + zeta W e) / W_d)^2) with e = x - 1, and the largest |x - 1| sampled over the dwell.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..kinematics.motion_law import MotionLaw
from .spectral import check_ratios, check_zeta

__all__ = ["TrainRun", "run_train", "residual_ode"]

RTOL, ATOL = 1e-11, 1e-13


@dataclass(frozen=True)
class TrainRun:
    """One run of the train: the residual and the sampled history (u, x, x', W_in, E_d, energy error)."""

    r: float
    zeta: float
    residual: float         # amplitude / lift at the dwell's start
    dwell_peak: float       # largest |x - 1| sampled over the dwell
    u: np.ndarray
    x: np.ndarray
    v: np.ndarray
    work_in: np.ndarray
    damper_loss: np.ndarray
    energy_error: np.ndarray  # (kinetic + spring + damper loss - work in) / max(work in), along the run


def _pieces(law) -> list[float]:
    if isinstance(law, MotionLaw):
        return sorted(set((0.0,) + law.T + (1.0,)))
    return list(law.breakpoints())


def run_train(law, r: float, zeta: float = 0.0, dwell: float = 2.0, samples: int = 200) -> TrainRun:
    """Integrate the train for the ratio r (> 0) and damping ratio zeta over the rise and ``dwell`` natural
    periods of the dwell."""
    from scipy.integrate import solve_ivp

    r = float(check_ratios(r)[0])
    z = check_zeta(zeta)
    if not (math.isfinite(dwell) and dwell > 0.0):
        raise ValueError(f"dwell {dwell!r}: allowed a number of natural periods > 0")
    W = 2.0 * math.pi * r
    c = 2.0 * z * W

    def rates(u, state):
        x, v = state[0], state[1]
        y, yd, _, _ = law.scalar(u) if u <= 1.0 else (1.0, 0.0, 0.0, 0.0)
        force = W * W * (y - x) + c * (yd - v)
        return [v, force, force * yd, c * (yd - v) ** 2]

    edges = _pieces(law)
    end = 1.0 + dwell / r
    state = np.zeros(4)
    us, xs = [np.zeros(1)], [state[None, :]]
    bounds = list(zip(edges[:-1], edges[1:])) + [(1.0, end)]
    for k, (a, b) in enumerate(bounds):
        if b <= a:
            continue
        t_eval = np.linspace(a, b, max(2, samples // len(bounds) if k < len(bounds) - 1 else samples))
        sol = solve_ivp(rates, (a, b), state, method="DOP853", rtol=RTOL, atol=ATOL, t_eval=t_eval,
                        first_step=min(1e-3, (b - a) / 10))
        if sol.status != 0:
            raise RuntimeError(f"train integration failed on u in ({a}, {b}): {sol.message}")
        state = sol.y[:, -1].copy()
        if k == len(bounds) - 2:
            at_dwell = state.copy()
        us.append(sol.t[1:])
        xs.append(sol.y[:, 1:].T)
    u = np.concatenate(us)
    Y = np.concatenate(xs)
    x, v, work, loss = Y.T
    e, ed = at_dwell[0] - 1.0, at_dwell[1]
    Wd = W * math.sqrt(1.0 - z * z)
    amplitude = math.hypot(e, (ed + z * W * e) / Wd)
    y = np.where(u <= 1.0, law.evaluate(np.minimum(u, 1.0))[0], 1.0)
    energy = 0.5 * v * v + 0.5 * W * W * (y - x) ** 2 + loss
    scale = max(float(np.max(np.abs(work))), 1e-300)
    dwell_peak = float(np.max(np.abs(x[u > 1.0] - 1.0)))
    return TrainRun(r=r, zeta=z, residual=amplitude, dwell_peak=dwell_peak, u=u, x=x, v=v, work_in=work,
                    damper_loss=loss, energy_error=(energy - work) / scale)


def residual_ode(law, r, zeta: float = 0.0) -> np.ndarray:
    """The residual / lift at each r by integrating the train (the running route; ``spectral.residual`` is the
    closed form)."""
    return np.array([run_train(law, float(x), zeta, dwell=0.5, samples=8).residual for x in check_ratios(r)])
