"""Residual vibration figures (Agg backend): residual / lift against r, one curve per law (log scale), and the
Pareto front of the worst residual against the jerk bound."""
from __future__ import annotations

from pathlib import Path
from typing import Mapping, Sequence

from . import save_figure


def plot_residual(curves: Mapping[str, tuple[Sequence[float], Sequence[float]]], title: str, path: Path,
                  limit: float | None = None, band: tuple[float, float] | None = None) -> Path:
    """curves: label -> (r, residual / lift). A horizontal line at ``limit``, the band shaded."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(8.0, 5.0))
    for label, (r, R) in curves.items():
        ax.semilogy(r, [max(v, 1e-7) for v in R], label=label)
    if limit is not None:
        ax.axhline(limit, color="black", linewidth=0.9, linestyle="--", label=f"limit {limit:g}")
    if band is not None:
        ax.axvspan(band[0], band[1], color="grey", alpha=0.15, label=f"band r = {band[0]:g}..{band[1]:g}")
    ax.set_xlabel("r = rise time / natural period of the train")
    ax.set_ylabel("residual amplitude / lift")
    ax.set_ylim(1e-5, None)
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=8)
    ax.set_title(title)
    return save_figure(plt, fig, path)


def plot_front(bounds: Sequence[float], worst: Sequence[float], classic: Mapping[str, tuple[float, float]],
               title: str, path: Path) -> Path:
    """The worst residual over the band against the jerk bound Cj; classic laws as points at their own Cj."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(7.0, 4.6))
    ax.plot(bounds, worst, "o-", label="optimised harmonic trapezoid")
    for label, (cj, w) in classic.items():
        ax.plot([cj], [w], "s", label=label)
    ax.set_xlabel("jerk bound Cj")
    ax.set_ylabel("worst residual / lift over the band")
    ax.grid(True, alpha=0.3)
    ax.legend(fontsize=8)
    ax.set_title(title)
    return save_figure(plt, fig, path)
