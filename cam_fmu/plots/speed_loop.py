"""Figure of speed-loop runs: speed error and armature voltage over time, one curve per run.

``runs``: {label: result of experiments.cosim.simulate_system} (columns 'time',
'cam.omega', 'controller.u', ...). Runs without and with feedforward go to the
left and right columns when both kinds are present (labels ending in '+ff').
"""
from __future__ import annotations

from pathlib import Path
from typing import Mapping

import numpy as np

from . import save_figure


def plot_speed_loop(runs: Mapping[str, Mapping[str, np.ndarray]], omega_set: Mapping[str, float],
                    ripples: Mapping[str, float], path: str | Path, title: str = "") -> Path:
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    groups = {"without feedforward": [k for k in runs if not k.endswith("+ff")],
              "with load-torque feedforward": [k for k in runs if k.endswith("+ff")]}
    groups = {g: labels for g, labels in groups.items() if labels}
    fig, axes = plt.subplots(2, len(groups), figsize=(6.5 * len(groups), 7), sharex=True, squeeze=False)
    for col, (group, labels) in enumerate(groups.items()):
        ax_e, ax_u = axes[0, col], axes[1, col]
        for label in labels:
            r = runs[label]
            line, = ax_e.plot(r["time"], omega_set[label] - r["cam.omega"], lw=0.9,
                              label=f"{label}: ripple {ripples[label]:.3g} rad/s")
            ax_u.plot(r["time"], r["controller.u"], lw=0.9, color=line.get_color(), label=label)
        ax_e.set_title(group, fontsize=10)
        ax_e.set_ylabel("speed error omega_set - omega [rad/s]")
        ax_u.set_ylabel("armature voltage u [V]")
        ax_u.set_xlabel("time t [s]")
        ax_e.legend(fontsize="small", title="peak-to-peak ripple, 2nd half", title_fontsize="small")
        for ax in (ax_e, ax_u):
            ax.grid(True, alpha=0.3)
    lim = max(abs(v) for ax in axes[0] for v in ax.get_ylim())
    for ax in axes[0]:
        ax.set_ylim(-lim, lim)
    ulo = min(ax.get_ylim()[0] for ax in axes[1])
    uhi = max(ax.get_ylim()[1] for ax in axes[1])
    for ax in axes[1]:
        ax.set_ylim(ulo, uhi)
    if title:
        fig.suptitle(title, fontsize=10)
    return save_figure(plt, fig, path)


def plot_two_speeds(runs: Mapping[str, Mapping[str, np.ndarray]], path: str | Path, title: str = "") -> Path:
    """A loop around a compliant shaft: the rotor's speed omega_m and the cam's omega over time, one panel per
    run (the columns 'cam.omega_m', 'cam.omega'), and the last 0.1 s of each magnified beside it."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(len(runs), 2, figsize=(12, 3.2 * len(runs)), squeeze=False,
                             gridspec_kw={"width_ratios": [2, 1]})
    for row, (label, r) in enumerate(runs.items()):
        t = r["time"]
        tail = t >= t[-1] - 0.1
        for ax, mask in ((axes[row, 0], slice(None)), (axes[row, 1], tail)):
            ax.plot(t[mask], r["cam.omega_m"][mask], color="tab:blue", linewidth=0.8, label="motor omega_m")
            ax.plot(t[mask], r["cam.omega"][mask], color="tab:orange", linewidth=0.8, label="cam omega")
            ax.grid(True, alpha=0.4)
        axes[row, 0].set_ylabel(f"{label}\n[rad/s]")
        axes[row, 1].set_title("last 0.1 s", fontsize=8)
    axes[0, 0].legend(fontsize=8)
    for ax in axes[-1]:
        ax.set_xlabel("time [s]")
    fig.suptitle(title)
    return save_figure(plt, fig, path)
