"""The figure of a scene (matplotlib, Agg backend, imported lazily).

Kinds (the scene's ``plot`` key; ``PLOTS`` is their one table):
- ``fig4``: J [kg m^2] and M [N m] over theta [deg] (paper fig. 4a, 4b);
- ``fig5``: M [N m] over theta [deg], one curve per run (paper fig. 5a, 5b);
- ``fig6``: omega [rad/s] over t [s], one curve per run (paper fig. 6);
- ``time``: omega, s, i, M over t, one curve per run.
"""
from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING, Any, Callable, Mapping

import numpy as np

if TYPE_CHECKING:
    from ..experiments.scenes import Scene

Results = Mapping[str, Mapping[str, np.ndarray]]


def _fig4(plt: Any, results: Results) -> tuple[Any, list]:
    fig, axes = plt.subplots(2, 1, figsize=(8, 7), sharex=True)
    for label, r in results.items():
        deg = np.degrees(r["theta"])
        name = None if len(results) == 1 else label
        axes[0].plot(deg, r["J"], label=name)
        axes[1].plot(deg, r["M"], label=name)
    axes[0].set_ylabel("equivalent inertia J [kg m$^2$]")
    axes[0].set_title("(a) J(theta) = J_m + m (ds/dtheta)$^2$")
    axes[1].set_ylabel("load torque M [N m]")
    axes[1].set_title("(b) total load torque M = M_f sgn(omega) + M_l")
    axes[1].set_xlabel("cam angle theta [deg]")
    _theta_ticks(axes[1])
    return fig, list(axes)


def _fig5(plt: Any, results: Results) -> tuple[Any, list]:
    fig, ax = plt.subplots(figsize=(8, 5))
    for label, r in results.items():
        ax.plot(np.degrees(r["theta"]), r["M"], label=label)
    ax.set_xlabel("cam angle theta [deg]")
    ax.set_ylabel("load torque M [N m]")
    _theta_ticks(ax)
    return fig, [ax]


def _fig6(plt: Any, results: Results) -> tuple[Any, list]:
    fig, ax = plt.subplots(figsize=(8, 5))
    for label, r in results.items():
        ax.plot(r["time"], r["omega"], label=label, lw=1.2)
    ax.set_xlabel("time t [s]")
    ax.set_ylabel("cam speed omega [rad/s]")
    return fig, [ax]


def _time(plt: Any, results: Results) -> tuple[Any, list]:
    quantities = (("omega", "omega [rad/s]", 1.0), ("s", "follower s [mm]", 1e3),
                  ("i", "current i [A]", 1.0), ("M", "load torque M [N m]", 1.0))
    fig, grid = plt.subplots(2, 2, figsize=(11, 7), sharex=True)
    axes = list(grid.flat)
    for ax, (name, ylabel, scale) in zip(axes, quantities):
        for label, r in results.items():
            ax.plot(r["time"], scale * np.asarray(r[name]), label=label, lw=1.0)
        ax.set_ylabel(ylabel)
    for ax in axes[2:]:
        ax.set_xlabel("time t [s]")
    return fig, axes


PLOTS: dict[str, Callable[[Any, Results], tuple[Any, list]]] = {
    "fig4": _fig4, "fig5": _fig5, "fig6": _fig6, "time": _time,
}


def plot_scene(scene: "Scene", results: Results, path: str | Path, engine: str = "reference") -> Path:
    """Draw the scene's figure from ``results`` ({label: outputs}) into ``path`` (PNG)."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = PLOTS[scene.plot](plt, results)
    for ax in axes:
        ax.grid(True, alpha=0.3)
        if len(results) > 1:
            ax.legend(fontsize="small")
    title = scene.description or scene.name
    if not title.startswith(scene.name):
        title = f"{scene.name}: {title}"
    fig.suptitle(f"{title}\n(engine: {engine})", fontsize=10)
    fig.tight_layout()
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return path


def _theta_ticks(ax) -> None:
    lo, hi = ax.get_xlim()
    if hi - lo > 90:
        ax.set_xticks(np.arange(0.0, 361.0, 45.0) if hi <= 400 else ax.get_xticks())
