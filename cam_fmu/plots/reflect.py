"""The reflected-load map's figure: J(theta) and M(theta) with its parts, over one turn (Agg backend)."""
from __future__ import annotations

import math
from pathlib import Path
from typing import Mapping


def plot_reflected(result: Mapping, title: str, path: Path) -> Path:
    """Panels over the cam angle [deg]: the inertia the motor sees, the load torque and its parts, and with a
    compliant shaft the resonance and anti-resonance [Hz]."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    deg = [math.degrees(t) for t in result["theta"]]
    compliant = "f_r" in result
    fig, axes = plt.subplots(3 if compliant else 2, 1, figsize=(8.0, 9.0 if compliant else 6.4), sharex=True)
    top, bottom = axes[0], axes[1]
    top.plot(deg, result["J"], color="tab:blue")
    top.set_ylabel("J seen by the motor [kg m$^2$]")
    top.grid(True, alpha=0.4)
    labels = {"M": "M (total)", "M_inertial": "inertial", "M_gravity": "gravity", "M_guide": "guide friction",
              "M_shaft": "shaft friction"}
    for name, label in labels.items():
        bottom.plot(deg, result[name], linewidth=2.0 if name == "M" else 1.0, label=label)
    bottom.set_ylabel("load torque [N m]")
    if compliant:
        freq = axes[2]
        freq.plot(deg, result["f_r"], label="resonance f_r")
        freq.plot(deg, result["f_a"], label="anti-resonance f_a")
        freq.set_ylabel("frequency [Hz]")
        freq.grid(True, alpha=0.4)
        freq.legend(fontsize=8)
    axes[-1].set_xlabel("cam angle [deg]")
    bottom.set_xlim(0.0, 360.0)
    bottom.grid(True, alpha=0.4)
    bottom.legend(fontsize=8, ncol=3)
    fig.suptitle(title)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return Path(path)
