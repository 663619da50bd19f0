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
"""
from __future__ import annotations

# Relative slack of the bound (integration error, rounding), of the energy scale |E| + r sum |W_in|.
# Every solver on every shipped voltage scene stays at least 0.74 of that scale below the
# bound (measured: losses dominate); a diverged or energy-making step overshoots it.
RELATIVE_SLACK = 1e-3


class EnergyBudget:
    """Tracks W_in and the bound for one drive (SI units)."""

    def __init__(self, model, theta: float, omega: float, i: float, s: float, J: float) -> None:
        self.model = model
        self.ratio = model.c_m / model.c_e
        self.work_in = 0.0  # J, electrical work delivered by the source
        self.work_abs = 0.0  # J, sum of |u int i dt|: the scale of the bookkeeping
        self.theta, self.i = theta, i
        self.e_mech0 = self._mech(omega, s, J)
        self.e_mag0 = 0.5 * model.L * i * i

    def _mech(self, omega: float, s: float, J: float) -> float:
        return 0.5 * J * omega * omega - self.model.F_gx * s

    def step(self, u: float, h: float, theta: float, i: float) -> None:
        """Account for one communication step of length h [s] under u [V] ending at theta, i."""
        m = self.model
        w = u * (u * h - m.c_e * (theta - self.theta) - m.L * (i - self.i)) / m.R
        self.work_in += w
        self.work_abs += abs(w)
        self.theta, self.i = theta, i

    def to_dict(self) -> dict:
        return {"work_in": self.work_in, "work_abs": self.work_abs, "theta": self.theta, "i": self.i,
                "e_mech0": self.e_mech0, "e_mag0": self.e_mag0}

    def restore(self, state: dict) -> None:
        for key in ("work_in", "work_abs", "theta", "i", "e_mech0", "e_mag0"):
            setattr(self, key, float(state[key]))

    def excess(self, omega: float, s: float, J: float, i: float) -> tuple[float, float]:
        """(energy above the bound [J], the tolerance [J]) at the current state."""
        e_mech = self._mech(omega, s, J)
        e_mag = 0.5 * self.model.L * i * i
        lhs = (e_mech - self.e_mech0) + self.ratio * (e_mag - self.e_mag0)
        rhs = self.ratio * self.work_in
        scale = abs(self.e_mech0) + abs(e_mech) + self.ratio * (self.work_abs + self.e_mag0 + e_mag) + 1e-12
        return lhs - rhs, RELATIVE_SLACK * scale
