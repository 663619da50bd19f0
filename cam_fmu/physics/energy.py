"""The energy bound every run of the voltage drive respects, checked on every published state.

Power balance of the drive (docs/model.md section 9): the source delivers
u i; copper (R i^2), shaft and guide friction and plastic impacts only take
energy away; the converter hands c_m i omega to the shaft for c_e i omega taken
from the circuit (r = c_m / c_e: the paper's constants create 0.75 %). Hence, with
E_mech = 1/2 J omega^2 - F_gx s (kinetic plus gravity potential) and
E_mag = 1/2 L i^2,

    Delta E_mech + r Delta E_mag <= r W_in,    W_in = int u i dt,

and over a step with u held, int i dt = (u h - c_e Delta theta - L Delta i) / R
exactly, so W_in needs no integration. A state above the bound by more than
the tolerance is not a result: a diverged or inaccurate solver made energy.

``EnergyBudget`` keeps that account for one drive; the run-time engine keeps
its own copy (it checks every published state).
"""
from __future__ import annotations

import math
from typing import Any

# Relative slack of the bound (integration error, rounding), of the energy scale |E| + r sum |W_in|.
# Every solver on every shipped voltage scene stays at least 0.74 of that scale below the
# bound (measured: losses dominate); a diverged or energy-making step overshoots it.
RELATIVE_SLACK = 1e-3


class EnergyBudget:
    """Tracks W_in [J] and the bound for one drive (SI units) from the state at its start.

    ``model`` gives c_e, c_m, L, R and F_gx (a physics.drive.DriveModel);
    theta [rad], omega [rad/s], i [A], s [m] and J [kg m2] are the start state.
    """

    def __init__(self, model: Any, theta: float, omega: float, i: float, s: float, J: float) -> None:
        self.c_e, self.L, self.R, self.F_gx = model.c_e, model.L, model.R, model.F_gx
        self.ratio = model.c_m / model.c_e  # r: shaft energy per unit of circuit energy
        self.work_in = 0.0  # J, electrical work delivered by the source
        self.work_abs = 0.0  # J, sum of |u int i dt|: the scale of the bookkeeping
        self.theta, self.i = theta, i
        self.e_mech0 = self._mech(omega, s, J)
        self.e_mag0 = 0.5 * self.L * i * i

    def _mech(self, omega: float, s: float, J: float) -> float:
        """E_mech = 1/2 J omega^2 - F_gx s [J]."""
        return 0.5 * J * omega * omega - self.F_gx * s

    def step(self, u: float, h: float, theta: float, i: float) -> None:
        """Account for one step of length h [s] under u [V] held, ending at theta [rad], i [A].

        u int i dt with int i dt = (u h - c_e Delta theta - L Delta i) / R, exact.
        """
        w = u * (u * h - self.c_e * (theta - self.theta) - self.L * (i - self.i)) / self.R
        self.work_in += w
        self.work_abs += abs(w)
        self.theta, self.i = theta, i

    def to_dict(self) -> dict[str, float]:
        """The account's state, JSON-serialisable."""
        return {"work_in": self.work_in, "work_abs": self.work_abs, "theta": self.theta, "i": self.i,
                "e_mech0": self.e_mech0, "e_mag0": self.e_mag0}

    def restore(self, state: dict[str, float]) -> None:
        """The account of ``to_dict``."""
        for key in ("work_in", "work_abs", "theta", "i", "e_mech0", "e_mag0"):
            setattr(self, key, float(state[key]))

    def surplus(self, omega: float, s: float, J: float, i: float) -> float:
        """Energy above the bound, less the tolerance [J]: > 0 means energy was created (inf: the energy
        overflowed, which counts as created)."""
        excess, tolerance = self.excess(omega, s, J, i)
        return excess - tolerance if math.isfinite(excess) and math.isfinite(tolerance) else math.inf

    def excess(self, omega: float, s: float, J: float, i: float) -> tuple[float, float]:
        """(energy above the bound [J], the tolerance [J]) at the state omega, s, J, i.

        The excess is Delta E_mech + r Delta E_mag - r W_in; the tolerance is
        RELATIVE_SLACK of |E_mech0| + |E_mech| + r (sum |W_in| + E_mag0 + E_mag) (+ 1e-12 J).
        """
        e_mech = self._mech(omega, s, J)
        e_mag = 0.5 * self.L * i * i
        lhs = (e_mech - self.e_mech0) + self.ratio * (e_mag - self.e_mag0)
        rhs = self.ratio * self.work_in
        scale = abs(self.e_mech0) + abs(e_mech) + self.ratio * (self.work_abs + self.e_mag0 + e_mag) + 1e-12
        return lhs - rhs, RELATIVE_SLACK * scale
