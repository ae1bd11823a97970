"""Pictures that move: a described mechanism following a trajectory, written as a GIF.

The pictures are :func:`robomech.multibody.animate`'s (the multibody layer's wireframe, written
with matplotlib's movie writers), so any mechanism with a description animates the same way; this
module adds what a report needs:

* :func:`assemble_path` assembles a described mechanism along a sequence of actuated coordinates
  as following it frame by frame does (one assembly branch): the input checks around the one
  branch-following assembly, :func:`robomech.verify._mujoco.assemble_along`;
* :func:`animate` is :func:`robomech.multibody.animate` (a GIF: every body drawn as its wireframe
  star, one colour per chain from the base; ground attachments, loop closures, one site's path);
* :func:`animation_figure` does both for a study and returns the report's :class:`Figure` with the
  data a test needs to check that the picture is the model's motion (:class:`Animation`).
"""

from __future__ import annotations

import time
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from numpy.typing import ArrayLike, NDArray

from robomech import multibody as mb
from robomech._validation import as_array
from robomech.multibody._animate import animate, frame_ms
from robomech.verify._mujoco import CONTINUATION_STEPS, assemble_along

from ._core import Figure

__all__ = ["CONTINUATION_STEPS", "Animation", "animate", "animation_figure", "assemble_path", "frame_ms"]


@dataclass(frozen=True)
class Animation:
    """A GIF written for a report, with what it shows.

    ``figure`` the report's record (path, caption, alt text); ``q (frames, nq)`` the configurations
    drawn, frame by frame; ``t (frames,)`` their times (s); ``site (frames, 3)`` the world position of
    the traced site in each frame (m); ``residual (frames,)`` the closure residual of each assembled
    frame (m) and ``converged (frames,)`` whether it assembled; ``seconds`` the assembly + render
    time; ``bytes`` the GIF's size.
    """

    figure: Figure
    q: NDArray[np.float64]
    t: NDArray[np.float64]
    site: NDArray[np.float64]
    residual: NDArray[np.float64]
    converged: NDArray[np.bool_]
    seconds: float
    bytes: int

    def summary(self) -> dict[str, float | int | str]:
        """The numbers a report records about the animation (``results.json``)."""
        return {
            "file": self.figure.path.name,
            "frames": int(self.q.shape[0]),
            "bytes": self.bytes,
            "seconds": self.seconds,
            "frames_assembled": int(np.sum(self.converged)),
            "max_closure_residual_m": float(np.max(self.residual)),
        }


def _check_mech(mech: object) -> mb.Mechanism:
    if not isinstance(mech, mb.Mechanism):
        raise ValueError(f"Expected mech to be a robomech.multibody.Mechanism, got {type(mech).__name__}.")
    return mech


def assemble_path(mech: mb.Mechanism, q_act: ArrayLike) -> mb.FKResult:
    """Assemble ``mech`` at each row of ``q_act (nt, n_act)`` on the branch of its reference pose.

    The input checks of a report's animation around
    :func:`robomech.verify._mujoco.assemble_along` (the one branch-following assembly: what following
    the path frame by frame gives, at the cost of two batched solves when the path stays on one
    branch).  Returns the stacked :class:`robomech.multibody.FKResult` (``q (nt, nq)``, ``residual``,
    ``converged``, ``iterations``, ``mode_changed``).
    """
    mech = _check_mech(mech)
    qa = as_array(q_act, "q_act", (len(mech.actuated),))
    if qa.ndim != 2 or qa.shape[0] < 1:
        raise ValueError(f"Expected q_act to have shape (nt, {len(mech.actuated)}), got {qa.shape}.")
    return assemble_along(mech, qa)


def animation_figure(
    mech: mb.Mechanism,
    q_act: ArrayLike,
    t: ArrayLike,
    out_dir: str | Path,
    name: str,
    caption: str,
    alt: str,
    *,
    site: str,
    fps: float = 20.0,
    title: str = "",
    view: tuple[float, float] | None = None,
    invert_z: bool = False,
) -> Animation:
    """Assemble ``mech`` along ``q_act (nt, n_act)`` at times ``t (nt,)`` and write ``out_dir/name.gif``.

    Returns the :class:`Animation`: the report's figure (``caption``, ``alt`` text) and the frames'
    configurations, times, traced ``site`` positions and closure residuals; a frame that does not
    assemble is drawn as the solver left it and flagged in ``converged`` (the study reports it).
    """
    t0 = time.perf_counter()
    mech = _check_mech(mech)
    tt = as_array(t, "t")
    qa = as_array(q_act, "q_act", (len(mech.actuated),))
    if tt.ndim != 1 or qa.shape[:-1] != tt.shape:
        raise ValueError(f"Expected t (nt,) and q_act (nt, n_act) to agree, got {tt.shape} and {qa.shape}.")
    if not isinstance(name, str) or not name or "/" in name:
        raise ValueError(f"Expected name to be a file stem (no folder), got {name!r}.")
    for text, what in ((caption, "caption"), (alt, "alt")):
        if not isinstance(text, str) or not text.strip():
            raise ValueError(f"Expected {what} to be a non-empty str, got {text!r}.")
    fk = assemble_path(mech, qa)
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    path = animate(
        mech, fk.q, out / f"{name}.gif", fps=fps, title=title, site=site, times=tt, view=view,
        invert_z=invert_z,
    )  # fmt: skip
    site_pos = mb.site_pose(mech, fk.q, site)[:, :3, 3]
    return Animation(
        figure=Figure(path=path, caption=caption, alt=alt),
        q=fk.q,
        t=tt,
        site=site_pos,
        residual=fk.residual,
        converged=fk.converged,
        seconds=time.perf_counter() - t0,
        bytes=path.stat().st_size,
    )
