"""Sobol sensitivity indices of a sweep's metrics (SALib): which varied parameter drives each metric.

``--sensitivity N`` runs a Saltelli design (sweep.Design with sample ("saltelli", N): N (d + 2) cases over the
--vary ranges, SALib.sample.sobol) like any sweep; ``indices`` then reads each metric back from the Parquet
dataset in case order and estimates, per parameter, the first-order index S1 (the share of the metric's
variance the parameter explains alone) and the total index ST (alone and in every interaction), each with the
half-width of its 95 % bootstrap confidence interval (SALib.analyze.sobol). A metric with a value that is not
finite (a failed case: NaN; a stalled cam's energy_per_turn: inf) gets NaN indices, said on stderr: the
estimators need every case.
"""
from __future__ import annotations

import csv
import math
import sys
from pathlib import Path
from typing import Any, Sequence

import numpy as np

COLUMNS = ("metric", "parameter", "S1", "S1_conf", "ST", "ST_conf")


def sobol_indices(problem: dict, y: np.ndarray, seed: int = 0) -> dict[str, np.ndarray]:
    """SALib's first-order and total indices of the outputs ``y`` (one per case of the Saltelli design of
    ``problem``, in its order): keys S1, S1_conf, ST, ST_conf, one entry per parameter (NaN when y has NaN)."""
    d = problem["num_vars"]
    if not np.all(np.isfinite(y)):
        return {key: np.full(d, math.nan) for key in COLUMNS[2:]}
    from SALib.analyze import sobol

    # the bootstrap seeded with seed + 1: SALib ignores a seed of 0 (``if seed:``) and the intervals then vary
    result = sobol.analyze(problem, np.asarray(y, dtype=float), calc_second_order=False, conf_level=0.95,
                           print_to_console=False, seed=seed + 1)
    return {key: np.asarray(result[key], dtype=float) for key in COLUMNS[2:]}


def indices(plan: Any, folder: str | Path) -> list[dict[str, Any]]:
    """One row (COLUMNS) per (metric, parameter) of the sweep ``plan`` (sweep_run.Plan with a Saltelli design)
    whose table is ``folder``."""
    from .sweep_store import iter_rows

    metrics = list(plan.metrics)
    y = {m: [] for m in metrics}
    for row in iter_rows(folder, metrics):
        for m in metrics:
            y[m].append(row[m])
    problem = plan.design.problem()
    rows = []
    for m in metrics:
        values = np.array(y[m], dtype=float)
        result = sobol_indices(problem, values, plan.design.seed)
        bad = int(np.sum(~np.isfinite(values)))
        for j, name in enumerate(problem["names"]):
            rows.append({"metric": m, "parameter": name, **{k: float(result[k][j]) for k in COLUMNS[2:]},
                         "not_finite": bad})
    return rows


def write_csv(rows: Sequence[dict[str, Any]], path: str | Path) -> Path:
    """COLUMNS, the indices with 17 digits."""
    path = Path(path)
    with open(path, "w", encoding="utf-8", newline="") as fh:
        out = csv.writer(fh, lineterminator="\n")
        out.writerow(COLUMNS)
        for row in rows:
            out.writerow([row["metric"], row["parameter"], *(repr(row[k]) for k in COLUMNS[2:])])
    return path


def format_table(rows: Sequence[dict[str, Any]]) -> str:
    """The indices as a text table, each metric's parameters by ST, largest first."""
    lines = [f"{'metric':<16} {'parameter':<14} {'S1':>7} {'+-':>6} {'ST':>7} {'+-':>6}"]
    for metric in dict.fromkeys(r["metric"] for r in rows):
        group = sorted((r for r in rows if r["metric"] == metric), key=lambda r: -np.nan_to_num(r["ST"], nan=-1))
        for r in group:
            lines.append(f"{metric:<16} {r['parameter']:<14} {r['S1']:7.3f} {r['S1_conf']:6.3f} "
                         f"{r['ST']:7.3f} {r['ST_conf']:6.3f}")
    return "\n".join(lines)


def report(plan: Any, folder: str | Path, out: str | Path, plot: bool = True) -> list[dict[str, Any]]:
    """indices of the sweep in ``folder``: DIR/<scene>_sensitivity.csv, the table on stdout, the bar chart."""
    rows = indices(plan, folder)
    name = plan.scene.name
    print(write_csv(rows, Path(out) / f"{name}_sensitivity.csv"))
    print(format_table(rows))
    if plot:
        from ..plots.sensitivity import plot_sensitivity

        print(plot_sensitivity(rows, Path(out) / f"{name}_sensitivity.png",
                               title=f"{name}: Sobol indices, {len(plan.design)} cases (Saltelli, N = "
                                     f"{plan.design.sample[1]})"))
    for metric, bad in {r["metric"]: r["not_finite"] for r in rows if r["not_finite"]}.items():
        print(f"# no indices for {metric}: {bad} of {len(plan.design)} cases not finite (failed: NaN; "
              "energy_per_turn = inf: the cam stalled)", file=sys.stderr)
    return rows
