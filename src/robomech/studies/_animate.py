"""Pictures that move: a described mechanism following a trajectory, written as a GIF (issue 13).

Uses the multibody layer's wireframe segments (``mb.body_segments``) and matplotlib's ``PillowWriter``
(pillow is a dependency of matplotlib), so any mechanism with a description animates the same way.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from robomech import multibody as mb
from robomech._validation import as_array, check_positive

from ._plot import plt

__all__ = ["animate"]


def animate(mech: mb.Mechanism, q: object, path: str | Path, *, fps: float = 20.0, title: str = "") -> Path:
    """Write a GIF of ``mech`` through the configurations ``q (nt, nq)`` (e.g. ``simulate(...).q``)."""
    from matplotlib.animation import PillowWriter

    if not isinstance(mech, mb.Mechanism):
        raise ValueError(f"Expected mech to be a robomech.multibody.Mechanism, got {type(mech).__name__}.")
    q = as_array(q, "q", (mech.nq,))
    if q.ndim != 2 or q.shape[0] < 1:
        raise ValueError(f"Expected q to have shape (nt, {mech.nq}), got {q.shape}.")
    fps = check_positive(fps, "fps")
    frames = [mb.body_segments(mech, qi) for qi in q]
    pts = np.concatenate([s.reshape(-1, 3) for f in frames for s in f.values()])
    c, r = pts.mean(axis=0), max(float(np.ptp(pts, axis=0).max()) / 2, 1e-3)
    fig = plt.figure(figsize=(4, 4))
    ax = fig.add_subplot(projection="3d")
    path = Path(path)
    writer = PillowWriter(fps=fps)
    with writer.saving(fig, str(path), dpi=80):
        for k, segs in enumerate(frames):
            ax.cla()
            for s in segs.values():
                for a, b in s:
                    ax.plot(*np.stack([a, b]).T, color="C0", lw=2)
            ax.set_xlim(c[0] - r, c[0] + r)
            ax.set_ylim(c[1] - r, c[1] + r)
            ax.set_zlim(c[2] - r, c[2] + r)
            ax.set_title(f"{title or mech.name}  frame {k + 1}/{len(frames)}")
            writer.grab_frame()
    plt.close(fig)
    return path
