"""Plots of a motion law (S, V, A, J, Q) and of a cam program (rise, return,
whole displacement diagram in mm over degrees).  Headless: Agg backend."""

from __future__ import annotations

import math
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from ..kinematics.cam_program import CamProgram  # noqa: E402
from ..kinematics.characteristics import Characteristics, characteristics as _characteristics  # noqa: E402
from ..kinematics.motion_law import MotionLaw  # noqa: E402


def _law_samples(law: MotionLaw, n: int = 4001) -> np.ndarray:
    # Dense grid plus both sides of every split point, so jumps show as jumps.
    t = np.linspace(0.0, 1.0, n)
    eps = 1e-9
    extra = [p + d for p in law.T for d in (-eps, eps) if 0.0 <= p + d <= 1.0]
    return np.unique(np.concatenate([t, extra]))


def plot_law_and_program(law: MotionLaw, program: CamProgram | None, path: str | Path,
                         title: str = "", characteristics: Characteristics | None = None) -> Path:
    """Write a PNG: S, V, A, J, Q of `law` and a summary; with `program`, also
    its rise, its return (s in mm and ds/dtheta in mm/rad over degrees) and the
    full displacement diagram over 0..360 deg."""
    c = characteristics or _characteristics(law)
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    rows = 3 if program is not None else 2
    fig, axes = plt.subplots(rows, 3, figsize=(15, 4.2 * rows), constrained_layout=True)
    fig.suptitle(f"Harmonic-trapezoid motion law {title}".strip(), fontsize=14)

    t = _law_samples(law)
    S, V, A, J = law.evaluate(t)
    panels = [("S (lift / h)", S), ("V = dS/dT", V), ("A = d²S/dT²", A),
              ("J = d³S/dT³", J), ("Q = A·V", A * V)]
    for ax, (label, y) in zip(axes[:2].flat, panels):
        ax.plot(t, y, lw=1.6)
        ax.set_xlabel("T = angle / stroke angle  [-]")
        ax.set_ylabel(label + "  [-]")
        ax.set_xlim(0, 1)
        ax.grid(alpha=0.3)
        for p in sorted(set(law.T)):
            ax.axvline(p, color="0.7", lw=0.8, ls=":")
    if c.jerk_unbounded:
        axJ = axes[1, 0]
        for p in c.jumps:
            axJ.axvline(p, color="tab:red", lw=1.2, ls="--")
        axJ.text(0.02, 0.95, "A jumps (red): J unbounded there", transform=axJ.transAxes,
                 va="top", color="tab:red", fontsize=9)

    info = axes[1, 2]
    info.axis("off")
    jm = "unbounded" if c.jerk_unbounded else f"{c.Jm:.4g}   at T = {c.at['Jm']:.4g}"
    lines = ["T1..T6 = " + ", ".join(f"{x:.4g}" for x in c.T), "",
             f"Vm  = {c.Vm:.4g}   at T = {c.at['Vm']:.4g}",
             f"Amp = {c.Amp:.4g},  Amm = {c.Amm:.4g}",
             f"Am  = {c.Am:.4g}   at T = {c.at['Am']:.4g}",
             f"Jm  = {jm}",
             f"Qm  = {c.Qm:.4g}   at T = {c.at['Qm']:.4g}"]
    info.text(0.0, 1.0, "\n".join(lines), va="top", family="monospace", fontsize=11)

    if program is not None:
        th = np.linspace(0.0, 2.0 * math.pi, 7201)
        s, ds, _, _ = program.evaluate(th)
        b1 = program.rise_angle
        b2 = b1 + program.upper_dwell
        b3 = b2 + program.return_angle
        stages = ((0.0, b1, "Rise", program.rise_law), (b2, b3, "Return", program.return_law))
        for ax, (lo, hi, name, stage_law) in zip(axes[2, :2], stages):
            m = (th >= lo) & (th <= hi)
            ax.plot(np.degrees(th[m]), s[m] * 1e3, lw=1.6, color="tab:blue", label="s")
            ax.set_xlabel("cam angle θ  [deg]")
            ax.set_ylabel("s  [mm]", color="tab:blue")
            ax.set_title(f"{name}: {math.degrees(hi - lo):.4g} deg, lift {program.lift * 1e3:.4g} mm\n"
                         "T = " + ", ".join(f"{x:.4g}" for x in stage_law.T), fontsize=10)
            ax.grid(alpha=0.3)
            ax2 = ax.twinx()
            ax2.plot(np.degrees(th[m]), ds[m] * 1e3, lw=1.2, color="tab:orange")
            ax2.set_ylabel("ds/dθ  [mm/rad]", color="tab:orange")
        ax = axes[2, 2]
        ax.plot(np.degrees(th), s * 1e3, lw=1.6)
        for lo, hi, col in ((b1, b2, "0.85"), (b3, 2 * math.pi, "0.85")):
            if hi > lo:
                ax.axvspan(math.degrees(lo), math.degrees(hi), color=col, alpha=0.6, lw=0)
        ax.set_xlim(0, 360)
        ax.set_xticks(np.arange(0, 361, 45))
        ax.set_xlabel("cam angle θ  [deg]")
        ax.set_ylabel("s  [mm]")
        ax.set_title("Displacement over one revolution (dwells shaded)")
        ax.grid(alpha=0.3)

    fig.savefig(path, dpi=110)
    plt.close(fig)
    return path
