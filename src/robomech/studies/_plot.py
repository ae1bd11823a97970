"""Figure helpers for studies (matplotlib with the non-interactive Agg backend)."""

from __future__ import annotations

from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt

from ._core import Figure

__all__ = ["plt", "save_figure"]


def save_figure(fig, out_dir: Path, name: str, caption: str) -> Figure:
    """Save ``fig`` as ``out_dir/name.png`` (150 dpi), close it, and return its report record."""
    out_dir.mkdir(parents=True, exist_ok=True)
    path = out_dir / f"{name}.png"
    fig.tight_layout()
    fig.savefig(path, dpi=150)
    plt.close(fig)
    return Figure(path=path, caption=caption)
