"""The follower train's cost (issue 41; docs/model.md 14.6; variants.py measures): the paper's cam at 3.5 V for 2 s
at 1 ms communication steps, without and with a 50 Hz train (k_train = 2e4 N/m, m_end = 0.2 kg, d_train = 2 N s/m),
shaft and guide friction off in both so the two differ by the train alone, per solver setting; an oscillating roller
without and with its torsional train of the same frequency; the speed drive at 25 rad/s the same (its steps are the
train's: the rigid speed drive takes one per communication step)."""
from __future__ import annotations

from typing import Any

from .variants import compare, report

STOP, STEP, U, OMEGA = 2.0, 1e-3, 3.5, 25.0
TRAIN = {"k_train": 2e4, "d_train": 2.0, "m_end": 0.2}
BASE = {"M_f": 0.0, "mu": 0.0}
# An oscillating roller (the arm of tests/engine/test_engine_follower_kinds.py, base circle 80 mm) and its torsional
# train of the same 50.3 Hz and damping ratio 0.016: J_end (2 pi 50.3)^2 = 200 N m/rad, 2 zeta sqrt(k J_end).
ARM = {"follower_type": "oscillating_roller", "lift_angle": 0.3, "arm_length": 0.15, "pivot_distance": 0.18,
       "J_arm": 2e-3, "m_arm": 0.2, "r_cm_arm": 0.07, "psi_0": 0.3, "r_b": 0.08}
ARM_TRAIN = {"k_train_arm": 200.0, "d_train_arm": 0.02, "J_end": 2e-3}
SETTINGS: dict[str, dict[str, Any]] = {
    "voltage rk45 (default)": {},
    "voltage rk4 h_max 1 ms": {"solver": "rk4", "h_max": 1e-3},
    "voltage rk23 rtol 1e-6": {"solver": "rk23", "rtol": 1e-6, "atol": 1e-9},
    "arm's torsional, rk45": ARM,
    "speed drive (default)": {"drive": "speed"},
}


def measure(rounds: int = 9) -> list[dict[str, Any]]:
    """Per setting: the rigid drive (base) and the train (variant), their times [ms], steps and ratios."""
    import numpy as np

    from ...physics.parameters import defaults

    table = np.array([(k * STEP, STEP, U, OMEGA, 0.0) for k in range(int(round(STOP / STEP)))])
    pairs = {label: (dict(defaults(), **BASE, **setting),
                     dict(defaults(), **BASE, **setting, **(ARM_TRAIN if setting is ARM else TRAIN)))
             for label, setting in SETTINGS.items()}
    return compare(pairs, table, rounds)


def run(ctx) -> int:
    """`cam-fmu bench train`: the table above, printed and written to OUT/train.csv."""
    return report(ctx, measure(3 if ctx.quick else 9), "train.csv")
