"""The follower train's cost (issue 41; docs/model.md 14.6): the engine in-process (``run_scene``, one call per run)
on the paper's cam at 3.5 V for 2 s at 1 ms communication steps, without and with a 50 Hz train (k_train = 2e4 N/m,
m_end = 0.2 kg, d_train = 2 N s/m), shaft and guide friction off in both so the two differ by the train alone; per
solver setting the wall time of a run and its internal steps, the best of ``rounds`` runs alternated, and their
ratios to the rigid run of the same setting: per run and per internal step. The speed drive at 25 rad/s the same
(its steps are the train's: the rigid speed drive takes one per communication step)."""
from __future__ import annotations

import csv
import time
from typing import Any

STOP, STEP, U, OMEGA = 2.0, 1e-3, 3.5, 25.0
TRAIN = {"k_train": 2e4, "d_train": 2.0, "m_end": 0.2}
BASE = {"M_f": 0.0, "mu": 0.0}
SETTINGS: dict[str, dict[str, Any]] = {
    "voltage rk45 (default)": {},
    "voltage rk4 h_max 1 ms": {"solver": "rk4", "h_max": 1e-3},
    "voltage rk23 rtol 1e-6": {"solver": "rk23", "rtol": 1e-6, "atol": 1e-9},
    "speed drive (default)": {"drive": "speed"},
}


def _table(params: dict[str, Any]):
    import numpy as np

    n = int(round(STOP / STEP))
    return np.array([(k * STEP, STEP, U, OMEGA, 0.0) for k in range(n)])


def _one(params: dict[str, Any]) -> tuple[float, int]:
    """(wall time [s], internal steps) of one run in one engine call."""
    from ...engine.simulator import DriveSimulator

    sim = DriveSimulator(params)
    table = _table(params)
    started = time.perf_counter()
    sim.run(table)
    return time.perf_counter() - started, sim.steps_taken


def measure(rounds: int = 9) -> list[dict[str, Any]]:
    """Per setting: rigid and train wall time [ms] and steps, the run's and the step's cost ratio."""
    from ...physics.parameters import defaults

    rows = []
    for label, setting in SETTINGS.items():
        rigid = dict(defaults(), **BASE, **setting)
        train = dict(rigid, **TRAIN)
        best = {"rigid": (float("inf"), 0), "train": (float("inf"), 0)}
        for _ in range(rounds):   # alternated: the machine's load moves both alike
            for name, params in (("rigid", rigid), ("train", train)):
                wall, steps = _one(params)
                if wall < best[name][0]:
                    best[name] = (wall, steps)
        (t_r, n_r), (t_t, n_t) = best["rigid"], best["train"]
        rows.append({"setting": label, "rigid_ms": t_r * 1e3, "rigid_steps": n_r, "train_ms": t_t * 1e3,
                     "train_steps": n_t, "run_ratio": t_t / t_r, "step_ratio": (t_t / n_t) / (t_r / n_r)})
    return rows


def run(ctx) -> int:
    """`cam-fmu bench train`: the table above, printed and written to OUT/train.csv."""
    rows = measure(3 if ctx.quick else 9)
    for r in rows:
        ctx.say(f"{r['setting']:24s} rigid {r['rigid_ms']:8.2f} ms {r['rigid_steps']:6d} steps | train "
                f"{r['train_ms']:8.2f} ms {r['train_steps']:6d} steps | run {r['run_ratio']:.2f}x, "
                f"per step {r['step_ratio']:.2f}x")
    with open(ctx.out / "train.csv", "w", newline="", encoding="utf-8") as f:
        writer = csv.DictWriter(f, fieldnames=list(rows[0]))
        writer.writeheader()
        writer.writerows(rows)
    return 0
