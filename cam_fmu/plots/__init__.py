"""Figures (matplotlib, Agg backend): motion laws and cam programs, cams, scenes, the speed loop."""
from __future__ import annotations

from pathlib import Path
from typing import Any


def save_figure(plt: Any, fig: Any, path: str | Path) -> Path:
    """Lay out, write (PNG, 110 dpi, parents created) and close a figure; return its path."""
    fig.tight_layout()
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return path
