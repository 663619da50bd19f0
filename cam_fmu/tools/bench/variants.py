"""What a feature of the drive costs: each variant run against its baseline, the same drive without it, in-process
(``DriveSimulator.run``, one engine call per run), the best of ``rounds`` runs alternated; per variant the wall time
of a run and its internal steps, and the ratios per run and per internal step. ``train.py`` and ``kinds.py`` name
their pairs."""
from __future__ import annotations

import csv
import time
from typing import Any, Mapping

import numpy as np


def _one(params: Mapping[str, Any], table: np.ndarray) -> tuple[float, int]:
    """(wall time [s], internal steps) of one run in one engine call."""
    from ...engine.simulator import DriveSimulator

    sim = DriveSimulator(params)
    started = time.perf_counter()
    sim.run(table)
    return time.perf_counter() - started, sim.steps_taken


def compare(pairs: Mapping[str, tuple[Mapping[str, Any], Mapping[str, Any]]], table: np.ndarray,
            rounds: int) -> list[dict[str, Any]]:
    """Per label (baseline parameters, variant parameters): base_ms, base_steps, variant_ms, variant_steps,
    run_ratio, step_ratio (the variant's over the baseline's)."""
    rows = []
    for label, (base, variant) in pairs.items():
        best = {"base": (float("inf"), 0), "variant": (float("inf"), 0)}
        for _ in range(rounds):   # alternated: the machine's load moves both alike
            for name, params in (("base", base), ("variant", variant)):
                wall, steps = _one(params, table)
                if wall < best[name][0]:
                    best[name] = (wall, steps)
        (t_b, n_b), (t_v, n_v) = best["base"], best["variant"]
        rows.append({"setting": label, "base_ms": t_b * 1e3, "base_steps": n_b, "variant_ms": t_v * 1e3,
                     "variant_steps": n_v, "run_ratio": t_v / t_b, "step_ratio": (t_v / n_v) / (t_b / n_b)})
    return rows


def report(ctx, rows: list[dict[str, Any]], csv_name: str) -> int:
    """Print one line a row and write OUT/<csv_name>; 0."""
    for r in rows:
        ctx.say(f"{r['setting']:26s} base {r['base_ms']:8.2f} ms {r['base_steps']:6d} steps | variant "
                f"{r['variant_ms']:8.2f} ms {r['variant_steps']:6d} steps | run {r['run_ratio']:.2f}x, "
                f"per step {r['step_ratio']:.2f}x")
    with open(ctx.out / csv_name, "w", newline="", encoding="utf-8") as f:
        writer = csv.DictWriter(f, fieldnames=list(rows[0]))
        writer.writeheader()
        writer.writerows(rows)
    return 0
