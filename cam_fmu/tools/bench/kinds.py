"""Each follower type's cost against the translating roller's on the same law (issue 40; docs/model.md 16;
variants.py measures): the consistent voltage drive at 3.5 V for 2 s at 1 ms steps, the default rk45, guide
friction off (the runs differ by the follower's geometry and inertia alone), base circle 80 mm, the arm's geometry of
tests/engine/test_engine_follower_kinds.py."""
from __future__ import annotations

from typing import Any

from .variants import compare, report

STOP, STEP, U = 2.0, 1e-3, 3.5
ARM = {"arm_length": 0.15, "pivot_distance": 0.18, "J_arm": 2e-3, "m_arm": 0.2, "r_cm_arm": 0.07, "psi_0": 0.3}
BASE = {"mu": 0.0, "r_b": 0.08}
KINDS: dict[str, dict[str, Any]] = {
    "translating_flat": {"follower_type": "translating_flat"},
    "oscillating_roller": {"follower_type": "oscillating_roller", "lift_angle": 0.3, **ARM},
    "oscillating_flat": {"follower_type": "oscillating_flat", "lift_angle": 0.15, **ARM},
}


def measure(rounds: int = 9) -> list[dict[str, Any]]:
    """Per type: the translating roller (base) and the type (variant), their times [ms], steps and ratios."""
    import numpy as np

    from ...physics.parameters import defaults

    table = np.array([(k * STEP, STEP, U, 1.0, 0.0) for k in range(int(round(STOP / STEP)))])
    pairs = {label: (dict(defaults(), **BASE), dict(defaults(), **BASE, **kind)) for label, kind in KINDS.items()}
    return compare(pairs, table, rounds)


def run(ctx) -> int:
    """`cam-fmu bench kinds`: the table above, printed and written to OUT/kinds.csv."""
    return report(ctx, measure(3 if ctx.quick else 9), "kinds.csv")
