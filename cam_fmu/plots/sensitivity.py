"""The Sobol indices' bar chart: one panel per metric, S1 and ST of each parameter with their 95 % intervals."""
from __future__ import annotations

from pathlib import Path
from typing import Any, Sequence

from . import save_figure


def plot_sensitivity(rows: Sequence[dict[str, Any]], path: str | Path, title: str = "") -> Path:
    """rows: sensitivity.indices (metric, parameter, S1, S1_conf, ST, ST_conf)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    import numpy as np

    metrics = list(dict.fromkeys(r["metric"] for r in rows))
    params = list(dict.fromkeys(r["parameter"] for r in rows))
    fig, axes = plt.subplots(len(metrics), 1, figsize=(1.2 * len(params) + 3.0, 2.4 * len(metrics)), squeeze=False)
    x = np.arange(len(params))
    for ax, metric in zip(axes[:, 0], metrics):
        by = {r["parameter"]: r for r in rows if r["metric"] == metric}
        for offset, key, label in ((-0.2, "S1", "first order S1"), (0.2, "ST", "total ST")):
            ax.bar(x + offset, [by[p][key] for p in params], 0.4, yerr=[by[p][key + "_conf"] for p in params],
                   capsize=3, label=label)
        ax.set_xticks(x, params)
        ax.set_ylabel(metric)
        ax.set_ylim(bottom=min(0.0, ax.get_ylim()[0]))
        ax.grid(True, axis="y", alpha=0.3)
    axes[0, 0].legend(fontsize="x-small")
    if title:
        fig.suptitle(title, fontsize=10)
    return save_figure(plt, fig, path)
