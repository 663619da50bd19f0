"""The reflected-load map's figure: J(theta) and M(theta) with its parts, over one turn (Agg backend)."""
from __future__ import annotations

import math
from pathlib import Path
from typing import Mapping


def plot_reflected(result: Mapping, title: str, path: Path) -> Path:
    """Two panels over the cam angle [deg]: the inertia the motor sees, and the load torque and its parts."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    deg = [math.degrees(t) for t in result["theta"]]
    fig, (top, bottom) = plt.subplots(2, 1, figsize=(8.0, 6.4), sharex=True)
    top.plot(deg, result["J"], color="tab:blue")
    top.set_ylabel("J seen by the motor [kg m$^2$]")
    top.grid(True, alpha=0.4)
    labels = {"M": "M (total)", "M_inertial": "inertial", "M_gravity": "gravity", "M_guide": "guide friction",
              "M_shaft": "shaft friction"}
    for name, label in labels.items():
        bottom.plot(deg, result[name], linewidth=2.0 if name == "M" else 1.0, label=label)
    bottom.set_ylabel("load torque [N m]")
    bottom.set_xlabel("cam angle [deg]")
    bottom.set_xlim(0.0, 360.0)
    bottom.grid(True, alpha=0.4)
    bottom.legend(fontsize=8, ncol=3)
    fig.suptitle(title)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return Path(path)
