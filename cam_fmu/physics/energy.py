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

The bookkeeping runs on every communication step, so ``EnergyBudget`` lives in
the drive kernel (kernel/drive_kernel.py, compiled where it can be).
"""
from __future__ import annotations

from ..kernel.drive_kernel import RELATIVE_SLACK, EnergyBudget  # noqa: F401  (the bound's one implementation)
