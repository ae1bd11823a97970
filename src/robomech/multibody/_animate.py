"""Pictures that move: any described mechanism along a sequence of configurations, as GIF or MP4.

Draws the wireframe of :func:`robomech.multibody.body_segments` (sliders drawn from their fixed end)
on matplotlib's Agg canvas, imported inside :func:`animate` (like :func:`robomech.multibody.draw`),
and writes the frames with matplotlib's movie writers: a GIF with ``PillowWriter`` (Pillow is a
dependency of matplotlib), an MP4 with ``FFMpegWriter`` where ``ffmpeg`` is on the PATH.

Every body is drawn as its star (one colour per chain from the base), ground attachments as
triangles, loop closures as circles, and optionally the whole path of one site (dotted) with the
site's current position marked.  For a GIF, the axes, panes and title are drawn once and each frame
draws only the moving lines over that background (blitting), and every frame is mapped to one shared
palette (no flicker between frames, a smaller file): a 60-frame GIF at 80 dpi (320 x 320 px, ~0.1 MB)
renders in about a second.  The axes limits are fixed over the motion and to scale.
"""

from __future__ import annotations

import shutil
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from numpy.typing import ArrayLike, NDArray

from robomech._validation import as_array, check_int, check_positive, check_real

from ._assembly import check_mechanism, check_q
from ._compile import compile_model
from ._model import Mechanism

__all__ = ["animate", "frame_ms"]

# Smallest drawn extent of an axis, as a fraction of the largest one: a planar motion keeps a
# visible (not collapsed) third axis.
MIN_AXIS_FRACTION = 0.25
# Palette of each GIF frame: a wireframe on a white background needs few colours (smaller file).
GIF_COLOURS = 64
# Ticks per axis (at most): the labels of a narrow axis must not overlap at 6 pt.
TICKS = 3
# Frames sampled (evenly over the motion) to build the GIF's one palette.
PALETTE_FRAMES = 6
# Margin around the motion's bounding box, as a fraction of its largest extent.
MARGIN = 0.08
# The file types animate writes, by suffix.
FORMATS = (".gif", ".mp4")


def frame_ms(fps: float) -> int:
    """The GIF frame delay (ms) for ``fps``: GIF stores delays in 1/100 s, and browsers replace a delay
    below 0.02 s by 0.1 s, so the delay is ``fps``'s rounded to 10 ms, at least 20 ms."""
    return 10 * max(2, round(100.0 / check_positive(fps, "fps")))


def _chain_colours(mech: Mechanism) -> dict[str, str]:
    """One matplotlib colour per chain from the base: a body gets the colour of its root ancestor."""
    parent = {b.name: b.parent for b in mech.bodies}
    roots: list[str] = []
    colours = {}
    for b in mech.bodies:
        root = b.name
        while parent[root] != "world":
            root = parent[root]
        if root not in roots:
            roots.append(root)
        colours[b.name] = f"C{roots.index(root) % 10}"
    return colours


@dataclass(frozen=True)
class _Drawing:
    """What a frame shows, for all frames at once (world coordinates, m)."""

    T: NDArray[np.float64]  # (nt, nb, 4, 4) body poses
    segments: NDArray[np.float64]  # (nt, ns, 2, 3) each body's star
    colours: list[str]  # (ns,) the colour of each segment (its chain)
    polygons: NDArray[np.float64]  # (nt, np, 2, 3) edges joining a body's >= 3 closure anchors
    ground: NDArray[np.float64]  # (nt, ng, 3) where top-level bodies are jointed to the ground
    closures: NDArray[np.float64]  # (nt, nc, 3) loop-closure points


def _drawing(mech: Mechanism, q: NDArray[np.float64]) -> _Drawing:
    """The wireframe of ``mb.body_segments`` for a batch ``q (nt, nq)``, with one change for sliders.

    Each body is a star from its root to every point it carries (children's roots, closure anchors,
    sites).  The root is the first joint's anchor where the parent holds it: for a hinge or ball the
    same point as ``body_segments`` uses, for a slide the fixed end of the stroke, so a prismatic leg
    is drawn at its actual length from its base (not as a rod of constant length sliding past it).
    """
    tree = mech.tree
    from ._compiled import compiled_body_poses  # numba loads on the first kernel call, not at import

    T = compiled_body_poses(compile_model(mech), q)  # (nt, nb, 4, 4)
    nt = q.shape[0]

    def world(b: int, x: ArrayLike) -> NDArray[np.float64]:
        return np.asarray(T[:, b, :3, :3] @ np.asarray(x, float) + T[:, b, :3, 3])

    pts: dict[int, list[NDArray[np.float64]]] = {i: [] for i in range(len(tree.body_names))}
    ground = []
    for i, b in enumerate(mech.bodies, start=1):
        if not b.joints:
            root = T[:, i, :3, 3]
        elif b.joints[0].type == "slide":
            held = T[:, int(tree.parent[i])] @ tree.T_off[i]  # the body's frame at zero stroke
            root = held[:, :3, :3] @ np.asarray(b.joints[0].pos) + held[:, :3, 3]
        else:
            root = world(i, b.joints[0].pos)
        pts[i].insert(0, root)
        pts[int(tree.parent[i])].append(root)
        if b.parent == "world" and b.joints:
            ground.append(root)
    closure_pts = []
    on_body: dict[int, list[NDArray[np.float64]]] = {}
    for c in mech.closures:
        b1, b2 = tree.body_index(c.body1), tree.body_index(c.body2)
        pts[b1].append(world(b1, c.anchor1 if c.kind != "rigid" else c.relpos))
        p2 = world(b2, c.anchor2)
        pts[b2].append(p2)
        closure_pts.append(p2)
        on_body.setdefault(b2, []).append(p2)
    for si in range(len(tree.site_names)):
        sb = int(tree.site_body[si])
        pts[sb].append((T[:, sb] @ tree.T_site[si])[:, :3, 3])
    colour_of = _chain_colours(mech)
    segs, colours = [], []
    for i, name in enumerate(tree.body_names):
        if i == 0 or len(pts[i]) < 2:
            continue
        for p in pts[i][1:]:
            segs.append(np.stack([pts[i][0], p], axis=1))  # (nt, 2, 3)
            colours.append(colour_of[name])
    polys = []
    for anchors in on_body.values():
        if len(anchors) >= 3:
            polys += [
                np.stack([anchors[k], anchors[(k + 1) % len(anchors)]], axis=1) for k in range(len(anchors))
            ]

    def stack(items: list[NDArray[np.float64]], tail: tuple[int, ...]) -> NDArray[np.float64]:
        return np.stack(items, axis=1) if items else np.zeros((nt, 0, *tail))

    return _Drawing(
        T=T,
        segments=stack(segs, (2, 3)),
        colours=colours,
        polygons=stack(polys, (2, 3)),
        ground=stack(ground, (3,)),
        closures=stack(closure_pts, (3,)),
    )


def _polyline(segments: NDArray[np.float64]) -> NDArray[np.float64]:
    """Segments ``(nt, ns, 2, 3)`` as one path per frame ``(nt, 3 ns, 3)``: a, b, NaN for each."""
    nt, ns = segments.shape[:2]
    gap = np.full((nt, ns, 1, 3), np.nan)
    return np.concatenate([segments, gap], axis=2).reshape(nt, 3 * ns, 3)


def _limits(pts: NDArray[np.float64]) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    lo, hi = np.nanmin(pts, axis=0), np.nanmax(pts, axis=0)
    span = max(float(np.max(hi - lo)), 1e-3)
    half = np.maximum((hi - lo) / 2, MIN_AXIS_FRACTION * span / 2) + MARGIN * span
    c = (lo + hi) / 2
    return c - half, c + half


def _writer_class(suffix: str):
    """The matplotlib movie writer for ``suffix``, or a ``ValueError`` saying what is missing."""
    from matplotlib.animation import FFMpegWriter, PillowWriter

    if suffix == ".gif":

        class GIFWriter(PillowWriter):
            """PillowWriter taking each frame from the (blitted) Agg canvas, saved with one shared
            palette and GIF's frame delay (:func:`frame_ms`)."""

            def grab_frame(self, **savefig_kwargs):
                rgba = np.asarray(self.fig.canvas.buffer_rgba())
                self._frames.append(np.array(rgba[..., :3]))

            def finish(self):
                from PIL import Image

                rgb = self._frames
                nt = len(rgb)
                # one palette for every frame (from a few frames side by side): a per-frame palette
                # maps the same background grey to different entries from frame to frame (flicker)
                picks = np.linspace(0, nt - 1, min(nt, PALETTE_FRAMES)).astype(int)
                sample = np.concatenate([rgb[k] for k in picks], 1)
                palette = Image.fromarray(sample).quantize(GIF_COLOURS, method=Image.Quantize.FASTOCTREE)
                images = [Image.fromarray(f).quantize(palette=palette, dither=Image.Dither.NONE) for f in rgb]
                images[0].save(
                    self.outfile, save_all=True, append_images=images[1:], duration=frame_ms(self.fps),
                    loop=0, disposal=1,
                )  # fmt: skip

        return GIFWriter
    if not FFMpegWriter.isAvailable() or shutil.which("ffmpeg") is None:
        raise ValueError(
            "Expected ffmpeg on the PATH to write an .mp4 (matplotlib's FFMpegWriter), got none: "
            "install ffmpeg or write a .gif."
        )
    return FFMpegWriter


def animate(
    mech: Mechanism,
    q: ArrayLike,
    path: str | Path,
    *,
    fps: float = 20.0,
    title: str = "",
    site: str | None = None,
    times: ArrayLike | None = None,
    dpi: int = 80,
    size: float = 4.0,
    view: tuple[float, float] | None = None,
    invert_z: bool = False,
) -> Path:
    """Write a GIF or MP4 of ``mech`` through the configurations ``q (nt, nq)`` (``simulate(...).q``).

    Parameters
    ----------
    mech : Mechanism
        The described mechanism.
    q : array_like, shape (nt, nq)
        One assembled configuration per frame (MuJoCo qpos).
    path : str or Path
        The file to write: ``.gif`` (matplotlib's ``PillowWriter``) or ``.mp4`` (``FFMpegWriter``,
        needs ``ffmpeg`` on the PATH).
    fps : float, optional
        Frames per second (a GIF stores its delay in 10 ms steps: rounded, at least 20 ms).
    title : str, optional
        Title above the drawing (default the mechanism's name).
    site : str, optional
        A site whose whole path is drawn dotted, with its position in the current frame marked.
    times : array_like, shape (nt,), optional
        Time of each frame (s), shown in the corner instead of the frame number.
    dpi, size : int, float, optional
        Resolution and side of the square picture (inches): ``size * dpi`` pixels.
    view : (float, float), optional
        Camera angles ``(elev, azim)`` (deg) of the 3-D axes.
    invert_z : bool, optional
        Draw z pointing down (a mechanism described in a frame whose z points down, e.g. a leg).

    Returns
    -------
    Path
        The file written.

    Raises
    ------
    ValueError
        On bad input, a suffix other than ``.gif`` / ``.mp4``, or an ``.mp4`` without ffmpeg.

    Examples
    --------
    >>> import numpy as np
    >>> from robomech import multibody as mb
    >>> mech = mb.gallery.load("four_bar")
    >>> fk = mb.forward_kinematics(mech, np.linspace(0.2, 1.2, 30)[:, None])
    >>> mb.animate(mech, fk.q, "four_bar.gif", site="coupler_point")   # doctest: +SKIP
    PosixPath('four_bar.gif')
    """
    mech = check_mechanism(mech)
    qa = as_array(q, "q", (mech.nq,))
    if qa.ndim != 2 or qa.shape[0] < 1:
        raise ValueError(f"Expected q to have shape (nt, {mech.nq}), got {qa.shape}.")
    nt = qa.shape[0]
    if not isinstance(path, (str, Path)) or not str(path):
        raise ValueError(f"Expected path to be a file path ending in .gif or .mp4, got {path!r}.")
    out = Path(path)
    if out.suffix.lower() not in FORMATS:
        raise ValueError(f"Expected path to end in .gif or .mp4, got {str(path)!r}.")
    fps = check_positive(fps, "fps")
    dpi = check_int(dpi, "dpi", low=10, high=600)
    size = check_positive(size, "size")
    if not isinstance(title, str):
        raise ValueError(f"Expected title to be a str, got {type(title).__name__}.")
    if site is not None and (not isinstance(site, str) or site not in mech.tree.site_names):
        raise ValueError(f"Expected site to be None or one of {list(mech.tree.site_names)}, got {site!r}.")
    tt = None
    if times is not None:
        tt = as_array(times, "times")
        if tt.shape != (nt,):
            raise ValueError(f"Expected times to have shape ({nt},) (one per frame), got {tt.shape}.")
    if view is not None:
        if not (isinstance(view, tuple) and len(view) == 2):
            raise ValueError(f"Expected view to be None or (elev, azim) in degrees, got {view!r}.")
        view = (check_real(view[0], "view (elev)"), check_real(view[1], "view (azim)"))
    if not isinstance(invert_z, bool):
        raise ValueError(f"Expected invert_z to be True or False, got {invert_z!r}.")
    qa = check_q(mech, qa)
    writer_class = _writer_class(out.suffix.lower())
    blit = out.suffix.lower() == ".gif"

    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure  # not pyplot: the user's backend and figures are left alone
    from matplotlib.ticker import MaxNLocator

    drawing = _drawing(mech, qa)
    site_path = None
    if site is not None:
        si = mech.tree.site_index(site)
        site_path = (drawing.T[:, mech.tree.site_body[si]] @ mech.tree.T_site[si])[:, :3, 3]
    allpts = [drawing.segments.reshape(nt, -1, 3), drawing.ground]
    if site_path is not None:
        allpts.append(site_path[:, None])
    lo, hi = _limits(np.concatenate(allpts, axis=1).reshape(-1, 3))

    fig = Figure(figsize=(size, size), dpi=dpi)
    canvas = FigureCanvasAgg(fig)  # the raster canvas whose buffer the frames are read from
    ax = fig.add_subplot(projection="3d")
    ax.set_xlim(lo[0], hi[0])
    ax.set_ylim(lo[1], hi[1])
    ax.set_zlim(lo[2], hi[2])
    ax.set_box_aspect(tuple(hi - lo))  # to scale
    if invert_z:
        ax.invert_zaxis()
    if view is not None:
        ax.view_init(elev=view[0], azim=view[1])
    ax.set_xlabel("x (m)", fontsize=7, labelpad=-4)
    ax.set_ylabel("y (m)", fontsize=7, labelpad=-4)
    ax.set_zlabel("z (m)", fontsize=7, labelpad=-4)
    ax.tick_params(labelsize=6, pad=-2)
    for axis in (ax.xaxis, ax.yaxis, ax.zaxis):
        axis.set_major_locator(MaxNLocator(TICKS))
    # one line per colour, its segments separated by NaN (a break in the drawn path)
    strokes = [
        (
            ax.plot([], [], [], color=c, lw=2)[0],
            _polyline(drawing.segments[:, np.array(drawing.colours) == c]),
        )
        for c in dict.fromkeys(drawing.colours)
    ]
    if drawing.polygons.shape[1]:
        strokes.append((ax.plot([], [], [], color="0.3", lw=1)[0], _polyline(drawing.polygons)))
    (ground,) = ax.plot([], [], [], "k^", ms=6, ls="none")
    (closures,) = ax.plot([], [], [], "o", ms=5, mfc="none", mec="C3", ls="none")
    marker = None
    if site_path is not None:
        ax.plot(*site_path.T, color="0.4", lw=1, ls=":")
        (marker,) = ax.plot([], [], [], "o", ms=4, color="k", ls="none")
    ax.set_title(title or mech.name, fontsize=9)  # static: part of the background
    clock = fig.text(0.02, 0.02, "", fontsize=8)  # the frame's time (few glyphs: text is the costly part)
    fig.subplots_adjust(left=0.0, right=0.9, bottom=0.03, top=0.95)

    dynamic = [line for line, _ in strokes]
    dynamic += [a for a in (ground, closures, clock, marker) if a is not None]
    background = None
    if blit:
        for a in dynamic:
            a.set_animated(True)  # drawn per frame over the static background (blitting)
        canvas.draw()
        background = canvas.copy_from_bbox(fig.bbox)
    writer = writer_class(fps=fps)
    with writer.saving(fig, out, dpi):
        for k in range(nt):
            for line, xyz in strokes:
                line.set_data_3d(*xyz[k].T)
            ground.set_data_3d(*drawing.ground[k].T)
            closures.set_data_3d(*drawing.closures[k].T)
            if marker is not None and site_path is not None:
                marker.set_data_3d(site_path[k : k + 1, 0], site_path[k : k + 1, 1], site_path[k : k + 1, 2])
            clock.set_text(f"t = {tt[k]:.2f} s" if tt is not None else f"frame {k + 1}/{nt}")
            if background is not None:
                canvas.restore_region(background)
                for a in dynamic:
                    fig.draw_artist(a)
            writer.grab_frame()
    return out
