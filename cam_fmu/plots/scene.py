"""The figure of a scene (matplotlib, Agg backend, imported lazily).

Kinds (the scene's ``plot`` key; ``PLOTS`` is their one table):
- ``fig4``: J [kg m^2] and M [N m] over theta [deg] (paper fig. 4a, 4b);
- ``fig5``: M [N m] over theta [deg], one curve per run (paper fig. 5a, 5b);
- ``fig6``: omega [rad/s] over t [s], one curve per run (paper fig. 6);
- ``time``: over t, one curve per run: omega, s, i, M for ``drive = "voltage"``;
  voltage [V] (the armature voltage the speed drive needs), i, omega, s, M, J for
  ``drive = "speed"`` (``TIME_PANELS``, keyed by the scene's drive);
- ``follower``: over t, one curve per run: the follower's gap to the cam s - s_cam [mm], its velocity v,
  acceleration a and the load torque M (the follower as a body of its own, docs/model.md section 13);
- ``train``: over t, one curve per run: the follower train's stretch s_end - s [mm] (its ringing about the static
  deflection), its force F_train, the end mass's acceleration and the load torque M (docs/model.md 14.6).

With 2+ runs, ``fig6`` and ``time`` draw below each quantity a smaller axes
"difference [unit]": every further run minus the primary (first) run on the
primary run's time grid (linear interpolation when the grids differ). Runs
that overlap on the main axes (L = 1 mH vs 0, c = 0.5 mm vs 0) differ there.
"""
from __future__ import annotations

from pathlib import Path
from typing import Any, Callable, Mapping, Protocol

import numpy as np

from . import save_figure

Results = Mapping[str, Mapping[str, np.ndarray]]


class Scene(Protocol):
    """What a figure reads of a scene (``experiments.scenes.Scene`` has it; plots import no experiments)."""

    name: str
    description: str
    plot: str   # a key of PLOTS
    drive: str  # 'voltage' or 'speed'


def _fig4(plt: Any, results: Results, drive: str = "speed") -> tuple[Any, list]:
    fig, axes = plt.subplots(3, 1, figsize=(8, 9.5), sharex=True)
    for label, r in results.items():
        deg = np.degrees(r["theta"])
        name = None if len(results) == 1 else label
        axes[0].plot(deg, r["J"], label=name)
        axes[1].plot(deg, r["M"], label=name)
    axes[0].set_ylabel("equivalent inertia J [kg m$^2$]")
    axes[0].set_title("(a) J(theta) = J_m + m (ds/dtheta)$^2$")
    axes[1].set_ylabel("load torque M [N m]")
    axes[1].set_title("(b) total load torque M = M_f sgn(omega) + M_l")
    _voltage_panel(axes[2], results)
    _theta_ticks(axes[2])
    return fig, list(axes)


def _fig5(plt: Any, results: Results, drive: str = "speed") -> tuple[Any, list]:
    fig, (ax, volts) = plt.subplots(2, 1, figsize=(8, 7.5), sharex=True, height_ratios=(2, 1))
    for label, r in results.items():
        ax.plot(np.degrees(r["theta"]), r["M"], label=label)
    ax.set_ylabel("load torque M [N m]")
    _voltage_panel(volts, results)
    _theta_ticks(volts)
    return fig, [ax, volts]


def _voltage_panel(ax: Any, results: Results) -> None:
    """The armature voltage the imposed motion needs, over the cam angle (speed drive)."""
    for label, r in results.items():
        ax.plot(np.degrees(r["theta"]), r["voltage"], label=None if len(results) == 1 else label)
    ax.set_ylabel("voltage [V]")
    ax.set_title("armature voltage the imposed speed needs (R i + c_e omega + L di/dt)", fontsize=9)
    ax.set_xlabel("cam angle theta [deg]")


def _fig6(plt: Any, results: Results, drive: str = "voltage") -> tuple[Any, list]:
    return _panels(plt, results, "time", (("omega", "cam speed omega", "rad/s", 1.0),), ncols=1, figsize=(8, 5))


TIME_PANELS = {
    "voltage": (("omega", "omega", "rad/s", 1.0), ("s", "follower s", "mm", 1e3),
                ("i", "current i", "A", 1.0), ("M", "load torque M", "N m", 1.0)),
    # speed drive: omega is imposed; what the converter must supply comes first
    "speed": (("voltage", "voltage", "V", 1.0), ("i", "current i", "A", 1.0),
              ("omega", "omega", "rad/s", 1.0), ("s", "follower s", "mm", 1e3),
              ("M", "load torque M", "N m", 1.0), ("J", "inertia J", "kg m$^2$", 1.0)),
}


def _time(plt: Any, results: Results, drive: str = "voltage") -> tuple[Any, list]:
    panels = TIME_PANELS[drive]
    return _panels(plt, results, "time", panels, ncols=2, figsize=(11, 3.6 * ((len(panels) + 1) // 2) + 0.6))


ARM_PANEL = ("psi", "arm angle psi", "deg", 180.0 / np.pi)   # an oscillating follower's motion (docs/model.md 16)


def _arm_time(plt: Any, results: Results, drive: str = "voltage") -> tuple[Any, list]:
    """_time with the arm's angle psi where the lift s would be (an oscillating follower's scene)."""
    panels = tuple(ARM_PANEL if panel[0] == "s" else panel for panel in TIME_PANELS[drive])
    return _panels(plt, results, "time", panels, ncols=2, figsize=(11, 3.6 * ((len(panels) + 1) // 2) + 0.6))


def _panels(plt: Any, results: Results, xname: str, quantities, ncols: int, figsize) -> tuple[Any, list]:
    """One axes per quantity (x = time [s]); with 2+ runs, below each a smaller axes of
    every further run's difference to the primary run (interpolated onto its grid)."""
    diff = len(results) > 1
    nrows = (len(quantities) + ncols - 1) // ncols
    ratios = [3, 1.3] * nrows if diff else [1] * nrows
    fig = plt.figure(figsize=(figsize[0], figsize[1] + (1.5 * nrows if diff else 0.0)))
    grid = fig.add_gridspec(len(ratios), ncols, height_ratios=ratios)
    labels = list(results)
    primary = results[labels[0]]
    axes = []
    for k, (name, title, unit, scale) in enumerate(quantities):
        row, col = divmod(k, ncols)
        ax = fig.add_subplot(grid[2 * row if diff else row, col])
        for n, (label, r) in enumerate(results.items()):
            ax.plot(r[xname], scale * np.asarray(r[name]), label=label, lw=1.2 if n == 0 else 1.0, color=f"C{n}")
        ax.set_ylabel(f"{title} [{unit}]")
        axes.append(ax)
        last = ax
        if diff:
            dax = fig.add_subplot(grid[2 * row + 1, col], sharex=ax)
            ax.tick_params(labelbottom=False)
            base = scale * np.asarray(primary[name])
            for n, label in enumerate(labels[1:], start=1):
                other = difference(primary[xname], results[label][xname], scale * np.asarray(results[label][name]), base)
                dax.plot(primary[xname], other, lw=1.0, color=f"C{n}", label=f"{label} - {labels[0]}")
            dax.axhline(0.0, color="0.5", lw=0.6)
            dax.set_ylabel(f"difference [{unit}]", fontsize="small")
            axes.append(dax)
            last = dax
        if row == nrows - 1 or k + ncols >= len(quantities):
            last.set_xlabel("time t [s]")
    return fig, axes


def difference(x0: np.ndarray, x: np.ndarray, y: np.ndarray, y0: np.ndarray) -> np.ndarray:
    """``y`` (sampled at ``x``) minus ``y0`` (sampled at ``x0``) on the grid ``x0``; interpolated
    linearly when the grids differ (NaN outside the other run's range)."""
    x0, x = np.asarray(x0, dtype=float), np.asarray(x, dtype=float)
    if x.shape == x0.shape and np.array_equal(x, x0):
        return np.asarray(y, dtype=float) - y0
    return np.interp(x0, x, y, left=np.nan, right=np.nan) - y0


FOLLOWER_PANELS = (("gap", "gap s - s_cam", "mm", 1e3), ("v", "follower v", "m/s", 1.0),
                   ("a", "follower a", "m/s$^2$", 1.0), ("M", "load torque M", "N m", 1.0))


def _follower(plt: Any, results: Results, drive: str = "speed") -> tuple[Any, list]:
    with_gap = {label: {**r, "gap": np.asarray(r["s"]) - np.asarray(r["s_cam"])} for label, r in results.items()}
    return _panels(plt, with_gap, "time", FOLLOWER_PANELS, ncols=2, figsize=(11, 7.8))


# kind -> draw(plt, results, drive) -> (figure, axes); 'time' picks its panels by the drive (TIME_PANELS)
TRAIN_PANELS = (("stretch", "train's stretch s_end - s", "mm", 1e3), ("F_train", "train's force F_train", "N", 1.0),
                ("a_end", "end mass acceleration a_end", "m/s$^2$", 1.0), ("M", "load torque M", "N m", 1.0))


def _train(plt: Any, results: Results, drive: str = "voltage") -> tuple[Any, list]:
    with_stretch = {label: {**r, "stretch": np.asarray(r["s_end"]) - np.asarray(r["s"])}
                    for label, r in results.items()}
    return _panels(plt, with_stretch, "time", TRAIN_PANELS, ncols=2, figsize=(11, 7.8))


PLOTS: dict[str, Callable[[Any, Results, str], tuple[Any, list]]] = {
    "fig4": _fig4, "fig5": _fig5, "fig6": _fig6, "time": _time, "arm_time": _arm_time, "follower": _follower,
    "train": _train,
}


def plot_scene(scene: Scene, results: Results, path: str | Path, engine: str = "reference") -> Path:
    """Draw the scene's figure from ``results`` ({label: outputs}) into ``path`` (PNG)."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig = draw_scene(plt, scene, results)
    title = scene.description or scene.name
    if not title.startswith(scene.name):
        title = f"{scene.name}: {title}"
    fig.suptitle(f"{title}\n(engine: {engine})", fontsize=10)
    return save_figure(plt, fig, path)


def draw_scene(plt: Any, scene: Scene, results: Results) -> Any:
    """The scene's matplotlib Figure (not saved), from ``PLOTS[scene.plot]``, grid and legends added."""
    fig, axes = PLOTS[scene.plot](plt, results, scene.drive)
    drawn = set()  # one legend per set of labels (main axes, difference axes)
    for ax in axes:
        ax.grid(True, alpha=0.3)
        labels = tuple(ax.get_legend_handles_labels()[1])
        if len(results) > 1 and labels and labels not in drawn:
            drawn.add(labels)
            ax.legend(fontsize="small")
    return fig


def _theta_ticks(ax) -> None:
    lo, hi = ax.get_xlim()
    if hi - lo > 90:
        ax.set_xticks(np.arange(0.0, 361.0, 45.0) if hi <= 400 else ax.get_xticks())
