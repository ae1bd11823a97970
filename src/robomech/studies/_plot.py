"""Figure helpers for studies.

Importing this module leaves matplotlib's backend alone (a notebook's inline backend, a user's GUI
backend): the studies create their figures with pyplot and close them once saved, so nothing is
shown.  A process that only writes files (the ``robomech`` command) selects the non-interactive Agg
backend itself with :func:`use_file_backend`; where no display exists matplotlib falls back to Agg.
"""

from __future__ import annotations

from pathlib import Path

import matplotlib
import matplotlib.pyplot as plt

from ._core import Figure

__all__ = ["plt", "save_figure", "use_file_backend"]


def use_file_backend() -> None:
    """Select matplotlib's Agg backend (files only, no window) for the rest of this process."""
    matplotlib.use("Agg")


def save_figure(fig, out_dir: Path, name: str, caption: str) -> Figure:
    """Save ``fig`` as ``out_dir/name.png`` (150 dpi), close it, and return its report record."""
    out_dir.mkdir(parents=True, exist_ok=True)
    path = out_dir / f"{name}.png"
    fig.tight_layout()
    fig.savefig(path, dpi=150)
    plt.close(fig)
    return Figure(path=path, caption=caption)
