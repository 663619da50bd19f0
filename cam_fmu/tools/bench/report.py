"""The error grid's report: rows, CSV, the choice table, the Pareto front and the figure."""
from __future__ import annotations

import csv
import math
from pathlib import Path
from typing import Sequence

from ...engine.solvers import SOLVERS
from .cases import CASES, LEVELS, error_column

COLUMNS = ("case", "kind", "solver", "setting", "h_max", "rtol", "atol", "default", "comm_step", "n_steps",
           "status", "reached_stop", "t_end", "theta_err", "omega_err", "s_err", "wall_s", "us_per_step", "rtf",
           "floor_us_per_step", "cost_ratio", "repeats", "pareto", "error")

def _fmt(value, spec: str, width: int) -> str:
    if value is None or value == "" or (isinstance(value, float) and math.isnan(value)):
        return f"{'-':>{width}}"
    return f"{value:>{width}{spec}}"


HEADER = (f"{'case':<15}{'kind':<6}{'solver':<7}{'setting':<12}{'comm[s]':>8}{'theta_err':>11}{'omega_err':>11}"
          f"{'s_err':>11}{'us/step':>10}{'RTF':>9}{'ratio':>8}  status")


def format_row(row: dict) -> str:
    setting = row["setting"] + ("*" if row["default"] else "")
    return (f"{row['case']:<15}{row['kind']:<6}{row['solver']:<7}{setting:<12}{row['comm_step']:>8g}"
            f"{_fmt(row['theta_err'], '.2e', 11)}{_fmt(row['omega_err'], '.2e', 11)}{_fmt(row['s_err'], '.2e', 11)}"
            f"{_fmt(row['us_per_step'], '.1f', 10)}{_fmt(row['rtf'], '.3g', 9)}{_fmt(row['cost_ratio'], '.2f', 8)}"
            f"  {row['status']}" + (f": {row['error']}" if row["error"] else ""))


def _row(**values) -> dict:
    row = {name: "" for name in COLUMNS}
    row.update(values)
    return row


def write_csv(rows: list[dict], path: Path, columns: Sequence[str] = COLUMNS) -> None:
    with open(path, "w", newline="", encoding="utf-8") as fh:
        writer = csv.DictWriter(fh, fieldnames=list(columns))
        writer.writeheader()
        for row in rows:
            writer.writerow({k: (repr(v) if isinstance(v, float) else v) for k, v in row.items() if k in columns})


# =========================================================================== summaries
CHOICE_COLUMNS = ("case", "comm_step", "ranked_by", "level", "solver", "setting", "error", "us_per_step",
                  "cost_ratio")


def choose(rows: list[dict]) -> list[dict]:
    """Per case, comm step and accuracy level: the FMU run of lowest cost ratio whose error is below it, the error
    being the case's ``error_column`` (theta's [rad]; s's [m] in the speed drive), named in ``ranked_by``."""
    choices = []
    keys = sorted({(r["case"], r["comm_step"]) for r in rows if r["kind"] == "fmu"},
                  key=lambda k: (CASES.index(k[0]) if k[0] in CASES else 99, k[1]))
    for case, comm in keys:
        column = error_column(case)
        runs = [r for r in rows if r["kind"] == "fmu" and r["case"] == case and r["comm_step"] == comm
                and r["status"] == "ok" and r[column] != ""]
        for level in LEVELS[column]:
            good = [r for r in runs if r[column] < level]
            best = min(good, key=lambda r: r["cost_ratio"]) if good else None
            choices.append({"case": case, "comm_step": comm, "ranked_by": column, "level": level,
                            "solver": best["solver"] if best else "none",
                            "setting": best["setting"] if best else "",
                            "error": best[column] if best else "",
                            "us_per_step": best["us_per_step"] if best else "",
                            "cost_ratio": best["cost_ratio"] if best else ""})
    return choices


def format_choices(choices: list[dict]) -> str:
    lines = ["# cheapest setting per accuracy level (the case's error < level: theta [rad], s [m] in the speed drive)",
             f"{'case':<15}{'comm[s]':>8}{'error':>10}{'level':>8}  {'solver':<7}{'setting':<12}{'error':>11}"
             f"{'us/step':>10}{'ratio':>8}"]
    for c in choices:
        lines.append(f"{c['case']:<15}{c['comm_step']:>8g}{c['ranked_by']:>10}{c['level']:>8g}  {c['solver']:<7}"
                     f"{c['setting']:<12}{_fmt(c['error'], '.2e', 11)}{_fmt(c['us_per_step'], '.1f', 10)}"
                     f"{_fmt(c['cost_ratio'], '.2f', 8)}")
    return "\n".join(lines)


# =========================================================================== Pareto front
def pareto(rows: list[dict]) -> list[dict]:
    """Mark every FMU row: ``pareto`` True when no other successful run of the same scene and comm step
    is at least as good in both error (the case's ``error_column``) and cost ratio and better in one (the
    non-dominated settings), False otherwise; rows without an error (floor, reference, failed runs) get "".
    Returns the front's rows, by scene, comm step and cost."""
    groups: dict = {}
    for r in rows:
        r["pareto"] = ""
        if r["kind"] == "fmu" and r["status"] == "ok" and r[error_column(r["case"])] != "" and r["cost_ratio"] != "":
            groups.setdefault((r["case"], r["comm_step"]), []).append(r)
    front = []
    for key in sorted(groups, key=lambda k: (CASES.index(k[0]) if k[0] in CASES else 99, k[1])):
        runs, e = groups[key], error_column(key[0])
        for r in runs:
            dominated = any(o is not r and o[e] <= r[e] and o["cost_ratio"] <= r["cost_ratio"]
                            and (o[e] < r[e] or o["cost_ratio"] < r["cost_ratio"]) for o in runs)
            r["pareto"] = not dominated
        front += sorted((r for r in runs if r["pareto"]), key=lambda r: r["cost_ratio"])
    return front


def format_pareto(front: list[dict]) -> str:
    lines = ["# Pareto front: the settings no other one beats in both error and cost (per scene, comm step; the "
             "error: theta's [rad], s's [m] in the speed drive)",
             f"{'case':<15}{'comm[s]':>8}  {'solver':<7}{'setting':<12}{'error':>11}{'us/step':>10}{'ratio':>8}"]
    for r in front:
        setting = r["setting"] + ("*" if r["default"] else "")
        lines.append(f"{r['case']:<15}{r['comm_step']:>8g}  {r['solver']:<7}{setting:<12}"
                     f"{_fmt(r[error_column(r['case'])], '.2e', 11)}{_fmt(r['us_per_step'], '.1f', 10)}"
                     f"{_fmt(r['cost_ratio'], '.2f', 8)}")
    return "\n".join(lines)


def plot(rows: list[dict], path: Path) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    import matplotlib.ticker

    cases = [c for c in CASES if any(r["case"] == c for r in rows)]
    palette = ("tab:red", "tab:blue", "tab:purple", "tab:green", "tab:orange", "tab:brown")
    colors = {name: palette[k % len(palette)] for k, name in enumerate(SOLVERS)}
    markers = {1e-4: "o", 1e-3: "s", 1e-2: "^"}
    fig, axes = plt.subplots(1, len(cases), figsize=(5.2 * len(cases), 4.6), squeeze=False)
    for ax, case in zip(axes[0], cases):
        e = error_column(case)
        floor_e = 1e-10 if e == "theta_err" else 1e-15   # rad, m: below it the log axis shows the floor
        runs = [r for r in rows if r["case"] == case and r["kind"] == "fmu" and r["status"] == "ok" and r[e] != ""]
        for solver, color in colors.items():
            for comm in sorted({r["comm_step"] for r in runs}):
                # in grid order (coarse to fine setting), not sorted by cost
                pts = [(r["cost_ratio"], max(r[e], floor_e)) for r in runs
                       if r["solver"] == solver and r["comm_step"] == comm]
                if pts:
                    ax.loglog(*zip(*pts), color=color, marker=markers.get(comm, "x"), linewidth=1.2,
                              label=f"{solver}, comm {comm:g} s")
        front = sorted((r for r in runs if r.get("pareto") is True), key=lambda r: (r["comm_step"], r["cost_ratio"]))
        for k, comm in enumerate(sorted({r["comm_step"] for r in front})):
            pts = [(r["cost_ratio"], max(r[e], floor_e)) for r in front if r["comm_step"] == comm]
            ax.loglog(*zip(*pts), color="k", linestyle=":", linewidth=1.0, marker=markers.get(comm, "x"),
                      markerfacecolor="none", markersize=11, zorder=5,
                      label="Pareto front (per comm step)" if k == 0 else None)
        ax.axhline(LEVELS[e][1], color="k", linestyle="--", linewidth=0.8)  # the choice table's middle level
        ax.set_ylim(floor_e, None)
        if e == "theta_err":
            ax.axhspan(1e-10, 1e-8, color="0.9", zorder=0)
            ax.text(0.02, 0.02, "below the reference's own accuracy (~1e-8 rad)", transform=ax.transAxes,
                    fontsize=7, color="0.4")
        ax.set_title(f"{case}")
        ax.set_xlabel("cost ratio [-]\n(us per comm step / the C floor's us per comm step)")
        ax.set_ylabel("max |theta - theta_ref| [rad]" if e == "theta_err" else "max |s - s_ref| [m] (theta imposed)")
        log_ticks(ax, matplotlib.ticker)
        ax.grid(True, which="major", alpha=0.4)
        ax.grid(True, which="minor", alpha=0.15)
    handles, labels = axes[0][0].get_legend_handles_labels()
    # below the axes, outside them; bbox_inches="tight" grows the canvas so nothing is clipped
    fig.legend(handles, labels, loc="upper center", bbox_to_anchor=(0.5, 0.0), ncol=min(4, max(1, len(labels))),
               fontsize=8, frameon=False)
    fig.suptitle("cam.fmu through fmpy: error against cost (dashed: the choice table's middle level; "
                 "open black markers, dotted: the Pareto front)")
    fig.tight_layout()
    fig.savefig(path, dpi=110, bbox_inches="tight")
    plt.close(fig)


def log_ticks(ax, ticker) -> None:
    """Both log axes: a labelled major tick at every decade (10^k); minor ticks labelled too
    when the axis spans less than about one decade (else it could carry no number at all)."""
    for axis in (ax.xaxis, ax.yaxis):
        axis.set_major_locator(ticker.LogLocator(base=10.0, numticks=30))
        axis.set_major_formatter(ticker.LogFormatterSciNotation(base=10.0))
        axis.set_minor_locator(ticker.LogLocator(base=10.0, subs=tuple(range(2, 10)), numticks=30))
        axis.set_minor_formatter(ticker.LogFormatterSciNotation(base=10.0, labelOnlyBase=False,
                                                                 minor_thresholds=(1.0, 0.5)))
