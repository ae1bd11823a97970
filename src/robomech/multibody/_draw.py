"""A wireframe drawing of any described mechanism at a configuration (matplotlib, imported lazily).

Each body is drawn as a star of segments from its first joint anchor (where it hangs on its parent)
to every other point it carries: its children's joint anchors, its closure anchors and its sites.
Ground attachments are drawn as triangles, loop closures as circles, sites as crosses.  This is the
only module of the layer that uses matplotlib (docs/architecture.md explains the exception).
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike

from ._assembly import check_mechanism, check_q
from ._compile import compile_model
from ._model import Mechanism

__all__ = ["body_segments", "draw", "view"]


def body_segments(mech: Mechanism, q: ArrayLike) -> dict[str, np.ndarray]:
    """World segments ``(k, 2, 3)`` per body name at one configuration ``q (nq,)`` (the drawing's data).

    Parameters
    ----------
    mech : Mechanism
        The described mechanism.
    q : array_like, shape (nq,)
        One configuration.

    Returns
    -------
    dict of str to ndarray, shape (k, 2, 3)
        Per body name, its segments (from the body's joint anchor to its children, closure anchors
        and sites) in world coordinates (m).

    Examples
    --------
    >>> from robomech import multibody as mb
    >>> mech = mb.gallery.load("four_bar")
    >>> {name: s.shape for name, s in mb.body_segments(mech, mech.q0).items()}
    {'crank': (1, 2, 3), 'coupler': (2, 2, 3), 'rocker': (1, 2, 3)}
    """
    mech = check_mechanism(mech)
    q = check_q(mech, q)
    if q.ndim != 1:
        raise ValueError(f"Expected q to have shape ({mech.nq},) (one configuration), got {q.shape}.")
    tree = mech.tree
    from ._compiled import compiled_body_poses  # numba loads on the first kernel call, not at import

    T = compiled_body_poses(compile_model(mech), q[None])[0]

    def world(b: int, x) -> np.ndarray:
        return T[b, :3, :3] @ np.asarray(x, float) + T[b, :3, 3]

    pts: dict[int, list[np.ndarray]] = {i: [] for i in range(len(tree.body_names))}
    for i, body in enumerate(mech.bodies, start=1):
        pts[i].insert(0, world(i, body.joints[0].pos) if body.joints else T[i, :3, 3])
        anchor = world(i, body.joints[0].pos) if body.joints else T[i, :3, 3]
        pts[int(tree.parent[i])].append(anchor)
    for c in mech.closures:
        b1, b2 = tree.body_index(c.body1), tree.body_index(c.body2)
        pts[b1].append(world(b1, c.anchor1 if c.kind != "rigid" else c.relpos))
        pts[b2].append(world(b2, c.anchor2))
    for s in range(len(tree.site_names)):
        b = int(tree.site_body[s])
        pts[b].append((T[b] @ tree.T_site[s])[:3, 3])
    out = {}
    for i, name in enumerate(tree.body_names):
        if i == 0 or len(pts[i]) < 2:
            continue
        root = pts[i][0]
        out[name] = np.array([[root, p] for p in pts[i][1:]])
    return out


def draw(
    mech: Mechanism, q: ArrayLike | None = None, ax=None, *, color: str = "C0", title: str | None = None
):
    """Draw ``mech`` at ``q (nq,)`` (default its reference configuration) on 3-D axes; returns the axes.

    Parameters
    ----------
    mech : Mechanism
        The described mechanism.
    q : array_like, shape (nq,), optional
        Configuration (default ``mech.q0``).
    ax : matplotlib Axes3D, optional
        Axes to draw on (default: new 3-D axes).
    color : str, optional
        Matplotlib colour of the segments.
    title : str, optional
        Axes title.

    Returns
    -------
    matplotlib Axes3D
        The axes drawn on.
    """
    import matplotlib.pyplot as plt

    mech = check_mechanism(mech)
    q = mech.q0 if q is None else q
    segs = body_segments(mech, q)
    from matplotlib.colors import is_color_like

    if not isinstance(color, str) or not is_color_like(color):
        raise ValueError(
            f"Expected color to be a matplotlib colour string ('C0', 'red', '#1f77b4'), got {color!r}."
        )
    if title is not None and not isinstance(title, str):
        raise ValueError(f"Expected title to be None or a string, got {title!r}.")
    qn = check_q(mech, q)
    tree = mech.tree
    from ._compiled import compiled_body_poses  # numba loads on the first kernel call, not at import

    T = compiled_body_poses(compile_model(mech), qn[None])[0]
    if ax is None:
        fig = plt.figure(figsize=(5, 5))
        ax = fig.add_subplot(projection="3d")
    elif getattr(ax, "name", None) != "3d":
        raise ValueError(f"Expected ax to be None or 3-D matplotlib axes, got {type(ax).__name__}.")
    for s in segs.values():
        for a, b in s:
            ax.plot(*np.stack([a, b]).T, color=color, lw=2)
    ground = [
        T[i, :3, :3] @ np.asarray(b.joints[0].pos) + T[i, :3, 3]
        for i, b in enumerate(mech.bodies, start=1)
        if b.parent == "world" and b.joints
    ]
    if ground:
        g = np.array(ground)
        ax.scatter(*g.T, marker="^", color="k", s=40)
    cl = []
    for c in mech.closures:
        b2 = tree.body_index(c.body2)
        cl.append(T[b2, :3, :3] @ np.asarray(c.anchor2) + T[b2, :3, 3])
    if cl:
        ax.scatter(*np.array(cl).T, marker="o", facecolors="none", edgecolors="C3", s=50)
    if len(tree.site_names):
        sp = np.array([(T[tree.site_body[s]] @ tree.T_site[s])[:3, 3] for s in range(len(tree.site_names))])
        ax.scatter(*sp.T, marker="x", color="C2", s=40)
    allp = np.concatenate([s.reshape(-1, 3) for s in segs.values()]) if segs else T[:, :3, 3]
    c, r = allp.mean(axis=0), max(np.ptp(allp, axis=0).max() / 2, 1e-3)
    ax.set_xlim(c[0] - r, c[0] + r)
    ax.set_ylim(c[1] - r, c[1] + r)
    ax.set_zlim(c[2] - r, c[2] + r)
    ax.set_xlabel("x (m)")
    ax.set_ylabel("y (m)")
    ax.set_zlabel("z (m)")
    ax.set_title(title if title is not None else mech.name)
    return ax


def view(mech: Mechanism, q: ArrayLike | None = None, **options):
    """Show ``mech`` live in the browser: :func:`robomech.viewer.view` (the ``view`` extra, viser).

    Parameters
    ----------
    mech : Mechanism
        The described mechanism.
    q : array_like, shape (nq,), optional
        Configuration shown first (default ``mech.q0``).
    **options
        ``site``, ``path``, ``times``, ``port``, ``open_browser``: see :func:`robomech.viewer.view`.

    Returns
    -------
    robomech.viewer.Viewer
        The running viewer (``.url``, ``.stop()``); displayed inline in Jupyter.
    """
    from robomech.viewer import view as _view  # the viewer layer sits above multibody (architecture.md)

    return _view(mech, q, **options)
