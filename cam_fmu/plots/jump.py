"""The jump figure: the closing force available against the force the follower's deceleration needs (Agg backend)."""
from __future__ import annotations

import math
from pathlib import Path
from typing import Mapping


def plot_jump(result: Mapping, title: str, path: Path) -> Path:
    """Over the cam angle [deg]: the spring's closing force F0 + k s - F_gx (with the guide friction at N = 0) and
    the inertial force m |s''| omega^2 the flank cannot give where s'' < 0, at each speed of ``result``; the
    follower leaves the cam where the second exceeds the first."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    deg = [math.degrees(t) for t in result["theta"]]
    fig, (top, bottom) = plt.subplots(2, 1, figsize=(8.0, 6.4), sharex=True)
    top.plot(deg, result["available"], linewidth=2.0, color="black", label="available: F0 + k s - F_gx")
    for key, label in result["speeds"].items():
        top.plot(deg, result[key], label=label)
    top.set_ylabel("force along the stroke [N]")
    top.grid(True, alpha=0.4)
    top.legend(fontsize=8)
    for key, label in result["speeds"].items():
        bottom.plot(deg, result["margin_" + key], label=label)
    bottom.axhline(0.0, color="black", linewidth=0.8)
    bottom.set_ylabel("contact force N cos(alpha) [N]")
    bottom.set_xlabel("cam angle [deg]")
    bottom.set_xlim(0.0, 360.0)
    bottom.grid(True, alpha=0.4)
    bottom.legend(fontsize=8)
    fig.suptitle(title)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return Path(path)
