"""The browser viewer: a viser server showing one described mechanism (viser imported lazily)."""

from __future__ import annotations

import contextlib
import io
import math
import socket
import threading
import time
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from robomech import multibody as mb
from robomech._validation import as_array, check_int
from robomech.multibody._assembly import check_mechanism, check_q
from robomech.multibody._repr import compact_repr

from ._geoms import Geom, mjcf_geoms
from ._scene import (
    AXIS_LENGTH_FRACTION,
    TRIAD_FRACTION,
    Scene,
    build_scene,
    cylinder_pose,
    matrix_to_wxyz,
    poses,
)

__all__ = ["Viewer", "view"]


HOST = "127.0.0.1"  # never another interface: the viewer is a local tool
FAILED_COLOUR = (220, 30, 30)
JOINT_COLOUR = (90, 90, 90)
ACTUATED_COLOUR = (240, 180, 0)
# Largest input change per continuation stage when a slider jumps (rad, or this fraction of the
# characteristic length for a slide): a drag follows the branch; a click far along the track is
# solved in stages of this size from the previous pose so that it stays on the same branch.
STAGE_RAD = 0.05
STAGE_LENGTH_FRACTION = 0.05
MAX_STAGES = 64
# Slider span around the reference value: a full turn for a hinge, the characteristic length for a
# slide (the description carries no joint limits).
SLIDE_SPAN_FRACTION = 1.0
SLIDER_STEPS = 400
# Playback: default frame rate (frames per second).
PLAYBACK_FPS = 20.0
# Camera distance from the centre of the drawing, in half-diagonals of its bounding box: the whole
# mechanism in view at viser's default field of view (~50 deg) with a margin.
CAMERA_DISTANCE = 2.6
# Bound on the wait for a browser's render of a screenshot (s).
SCREENSHOT_TIMEOUT = 20.0


@dataclass(frozen=True)
class Pose:
    """What the viewer shows: configuration ``q (nq,)``, actuated ``q_act``, whether it assembled,
    its closure residual (m), the singularity measures of the output site (None without a site) and
    a one-line status."""

    __repr__ = compact_repr

    q: NDArray[np.float64]
    q_act: NDArray[np.float64]
    converged: bool
    residual: float
    singularity: Any
    status: str


def _free_port() -> int:
    with socket.socket(socket.AF_INET, socket.SOCK_STREAM) as s:
        s.bind((HOST, 0))
        return int(s.getsockname()[1])


def _fmt(x: float) -> str:
    return f"{x:.4g}" if np.isfinite(x) else str(x)


class Viewer:
    """A running viewer of one mechanism (returned by :func:`view`; stop it with ``stop()``).

    Attributes
    ----------
    url : str
        Where the page is served (``http://127.0.0.1:PORT``).
    mech : robomech.multibody.Mechanism
        The mechanism shown.
    pose : Pose
        The current configuration, whether it assembled, its residual and singularity measures.

    In Jupyter, a ``Viewer`` as the last expression of a cell displays the live page inline (an
    iframe of :attr:`url`).
    """

    def __init__(
        self,
        mech: mb.Mechanism,
        q: NDArray[np.float64],
        *,
        port: int,
        site: str | None,
        path: NDArray[np.float64] | None,
        times: NDArray[np.float64] | None,
        geoms: tuple[Geom, ...] = (),
    ) -> None:
        try:
            import viser
        except ImportError as exc:  # pragma: no cover - exercised only without the optional extra
            raise ImportError("robomech's viewer needs viser: pip install 'robomech[view]'.") from exc
        self.mech = mech
        self.site = site
        self._scene: Scene = build_scene(mech)
        self._geoms = geoms
        self._lock = threading.RLock()
        self._syncing = False
        self._path = path
        self._times = times
        self._playing = threading.Event()
        self._closed = threading.Event()
        self._addr = [mech.qpos_address(j) for j in mech.actuated]
        # viser (1.1) prints a banner with rich.print even with verbose=False; in Jupyter rich shows
        # it as an output of the cell, above the viewer.  The caller prints the URL instead: rich's
        # console is quiet while the server starts.
        import rich

        console = rich.get_console()
        quiet, console.quiet = console.quiet, True
        try:
            with contextlib.redirect_stdout(io.StringIO()):
                self._server = viser.ViserServer(
                    host=HOST, port=port, label=f"robomech: {mech.name}", verbose=False
                )
        finally:
            console.quiet = quiet
        self.port = int(self._server.get_port())
        self.url = f"http://{HOST}:{self.port}"
        self._nodes: list[tuple[Any, tuple[int, int, int]]] = []  # (handle, normal colour)
        self._frames: dict[int, Any] = {}
        self._good = np.asarray(mech.q0, float)  # the last assembled pose: where a failed solve restarts
        self.pose: Pose | None = None
        self._build_scene()
        self._build_gui()
        self._show_q(q, "initial configuration")
        self._player = threading.Thread(target=self._play_loop, daemon=True, name="robomech-view-play")
        self._player.start()

    # -- scene --------------------------------------------------------------------------------------
    def _build_scene(self) -> None:
        sc, srv = self._scene, self._server
        L = sc.length
        srv.scene.set_up_direction("+z")
        srv.scene.add_grid("/grid", width=4 * L, height=4 * L, cell_size=L / 4, plane="xy")
        for b, name in enumerate(sc.body_names):
            self._frames[b] = srv.scene.add_frame(
                f"/bodies/{b}_{name}", show_axes=False, axes_length=TRIAD_FRACTION * L, axes_radius=L / 400
            )
        self._body_axes = [
            srv.scene.add_frame(
                f"/bodies/{b}_{name}/frame",
                axes_length=TRIAD_FRACTION * L,
                axes_radius=L / 300,
                visible=False,
            )
            for b, name in enumerate(sc.body_names)
            if b > 0
        ]
        for k, link in enumerate(sc.links):
            wxyz, centre, h = cylinder_pose(link.a, link.b)
            colour = sc.colour[link.body]
            node = srv.scene.add_cylinder(
                f"/bodies/{link.body}_{sc.body_names[link.body]}/link{k}",
                radius=sc.link_radius,
                height=h,
                color=colour,
                wxyz=tuple(wxyz),
                position=tuple(centre),
            )
            self._nodes.append((node, colour))
        self._links = [node for node, _ in self._nodes]
        self._geom_nodes = self._add_geoms()
        self._axes: list[Any] = []
        for j in sc.joints:
            parent = f"/bodies/{j.body}_{sc.body_names[j.body]}"
            colour = ACTUATED_COLOUR if j.actuated else JOINT_COLOUR
            joint_node = srv.scene.add_icosphere(
                f"{parent}/joint_{j.name}", radius=sc.joint_radius, color=colour, position=tuple(j.pos)
            )
            self._nodes.append((joint_node, colour))
            if j.axis is not None:
                half = 0.5 * AXIS_LENGTH_FRACTION * L * j.axis
                seg = np.array([[j.pos - half, j.pos + half]])
                self._axes.append(
                    srv.scene.add_line_segments(
                        f"{parent}/axis_{j.name}",
                        points=seg,
                        colors=np.array(colour),
                        thickness=3.0,
                        thickness_units="screen",
                    )
                )
        self._sites = []
        for s in sc.sites:
            self._sites.append(
                srv.scene.add_frame(
                    f"/bodies/{s.body}_{sc.body_names[s.body]}/site_{s.name}",
                    axes_length=TRIAD_FRACTION * L,
                    axes_radius=L / 250,
                    wxyz=tuple(matrix_to_wxyz(s.T[:3, :3])),
                    position=tuple(s.T[:3, 3]),
                )
            )
        # the camera frames the whole drawing at q0 (links, joints, sites), from above one corner
        T0 = poses(self.mech, np.asarray(self.mech.q0, float))
        pts = [T0[k.body, :3, :3] @ p + T0[k.body, :3, 3] for k in sc.links for p in (k.a, k.b)]
        pts += [T0[b, :3, 3] for b in range(len(sc.body_names))]
        lo, hi = np.min(pts, axis=0), np.max(pts, axis=0)
        centre, radius = (lo + hi) / 2, max(float(np.linalg.norm(hi - lo)) / 2, L / 2)
        direction = np.array([1.0, -1.0, 0.75]) / np.linalg.norm([1.0, -1.0, 0.75])
        self._server.initial_camera.position = tuple(centre + CAMERA_DISTANCE * radius * direction)
        self._server.initial_camera.look_at = tuple(centre)

    def _add_geoms(self) -> list[Any]:
        """The MJCF geoms, each under its body's frame (a frame per geom carries its pose)."""
        srv, names = self._server.scene, self._scene.body_names
        index = {n: b for b, n in enumerate(names)}
        nodes = []
        for k, g in enumerate(self._geoms):
            b = index.get(g.body, 0 if g.body == "world" else None)
            if b is None:
                continue  # a body the description does not have (e.g. an auxiliary one)
            base = f"/bodies/{b}_{names[b]}/geom{k}"
            frame = srv.add_frame(base, show_axes=False, wxyz=tuple(g.quat), position=tuple(g.pos))
            nodes.append(frame)
            colour = (
                round(255 * float(g.rgba[0])),
                round(255 * float(g.rgba[1])),
                round(255 * float(g.rgba[2])),
            )
            opacity = float(g.rgba[3]) if g.rgba[3] < 1 else None
            shapes: list[Any] = []
            r = float(g.size[0])
            if g.type == "sphere":
                shapes.append(srv.add_icosphere(f"{base}/s", radius=r, color=colour, opacity=opacity))
            elif g.type == "ellipsoid":
                shapes.append(
                    srv.add_icosphere(f"{base}/s", radius=1.0, color=colour, opacity=opacity,
                                      scale=(float(g.size[0]), float(g.size[1]), float(g.size[2])))
                )  # fmt: skip
            elif g.type in ("capsule", "cylinder"):
                h = 2 * float(g.size[1])
                shapes.append(
                    srv.add_cylinder(f"{base}/c", radius=r, height=h, color=colour, opacity=opacity)
                )
                if g.type == "capsule":
                    for end, z in (("a", -h / 2), ("b", h / 2)):
                        shapes.append(
                            srv.add_icosphere(f"{base}/{end}", radius=r, color=colour, opacity=opacity,
                                              position=(0.0, 0.0, z))
                        )  # fmt: skip
            elif g.type == "box":
                shapes.append(
                    srv.add_box(
                        f"{base}/b", color=colour, dimensions=2 * np.asarray(g.size[:3]), opacity=opacity
                    )
                )
            elif g.type == "mesh" and g.vertices is not None and g.faces is not None:
                shapes.append(
                    srv.add_mesh_simple(f"{base}/m", g.vertices, g.faces, color=colour, opacity=opacity)
                )
            self._nodes += [(shape, colour) for shape in shapes]
        return nodes

    def _place(self, q: NDArray[np.float64]) -> None:
        T = poses(self.mech, q)
        if not np.all(np.isfinite(T)):
            return  # a NaN pose (a failed solve from non-finite inputs) keeps the last drawn one
        with self._server.atomic():
            for b, frame in self._frames.items():
                frame.wxyz = tuple(matrix_to_wxyz(T[b, :3, :3]))
                frame.position = tuple(T[b, :3, 3])

    def _paint(self, ok: bool) -> None:
        for node, colour in self._nodes:
            node.color = colour if ok else FAILED_COLOUR

    # -- gui ------------------------------------------------------------------------------------------
    def _build_gui(self) -> None:
        gui, mech = self._server.gui, self.mech
        gui.add_markdown(f"**{mech.name}**: {len(mech.bodies)} bodies, {len(mech.closures)} closures")
        self._status = gui.add_markdown("")
        self._sliders = []
        with gui.add_folder("Actuated joints"):
            q0 = np.asarray(mech.q0, float)
            for name, a in zip(mech.actuated, self._addr, strict=True):
                joint = mech.joint(name)
                span = math.pi if joint.type == "hinge" else SLIDE_SPAN_FRACTION * float(mech.length)
                unit = "rad" if joint.type == "hinge" else "m"
                lo, hi = float(q0[a] - span), float(q0[a] + span)
                step = float(f"{(hi - lo) / SLIDER_STEPS:.2g}")
                s = gui.add_slider(f"{name} ({unit})", min=lo, max=hi, step=step, initial_value=float(q0[a]))
                s.on_update(self._on_slider)
                self._sliders.append(s)
            reset = gui.add_button("Reset to reference pose")
            reset.on_click(self._on_reset)
        with gui.add_folder("Show"):
            toggles: list[tuple[str, list[Any], bool]] = [("joint axes", self._axes, True)]
            if self._geom_nodes:  # the file's shapes; the links (the kinematic skeleton) on request
                toggles += [("MJCF geoms", self._geom_nodes, True), ("links", self._links, False)]
                self._set_visible(self._links, False)
            for label, nodes, initial in (
                *toggles,
                ("sites", self._sites, True),
                ("body frames", self._body_axes, False),
            ):
                box = gui.add_checkbox(label, initial_value=initial)
                box.on_update(self._toggler(nodes))
        self._measures = gui.add_markdown("")
        self._frame_slider = None
        if self._path is not None:
            with gui.add_folder("Playback"):
                nt = self._path.shape[0]
                self._frame_slider = gui.add_slider("frame", min=0, max=nt - 1, step=1, initial_value=0)
                self._frame_slider.on_update(lambda ev: self._show_frame(int(ev.target.value)))
                self._fps = gui.add_number("frames per second", PLAYBACK_FPS, min=0.5, max=240.0, step=0.5)
                self._play_button = gui.add_button("Play / pause")
                self._play_button.on_click(lambda _: self._toggle_play())
        shot = gui.add_button("Screenshot (PNG)")
        shot.on_click(self._on_screenshot)

    def _toggler(self, nodes: list[Any]) -> Any:
        def toggle(event: Any) -> None:
            self._set_visible(nodes, bool(event.target.value))

        return toggle

    def _on_reset(self, _event: Any) -> None:
        self.set_q(np.asarray(self.mech.q0, float))

    @staticmethod
    def _set_visible(nodes: list[Any], visible: bool) -> None:
        for n in nodes:
            n.visible = bool(visible)

    def _slider_values(self) -> NDArray[np.float64]:
        return np.array([float(s.value) for s in self._sliders])

    def _on_slider(self, _event: Any) -> None:
        if self._syncing:
            return
        self.set_q_act(self._slider_values())

    # -- state ----------------------------------------------------------------------------------------
    def _evaluate(self, q: NDArray[np.float64], *, converged: bool, residual: float, note: str) -> Pose:
        qa = np.asarray(q, float)[self._addr]
        sing = None
        if self.site is not None and converged and np.all(np.isfinite(q)):
            sing = mb.singularities(self.mech, q, self.site)
        if converged:
            status = f"assembled ({note}): closure residual {_fmt(residual)} m"
        else:
            status = f"did not assemble: residual {_fmt(residual)} m; drawn as the solver left it"
        return Pose(q=np.array(q, float), q_act=qa, converged=bool(converged), residual=float(residual),
                    singularity=sing, status=status)  # fmt: skip

    def _show(self, pose: Pose) -> None:
        self._place(pose.q)
        self._paint(pose.converged)
        colour = "green" if pose.converged else "red"
        q_text = ", ".join(f"{x:.4f}" for x in pose.q)
        self._status.content = (
            f'<span style="color:{colour}">**{pose.status}**</span>\n\n'
            f"q_act = [{', '.join(f'{x:.4f}' for x in pose.q_act)}]\n\n"
            f"q = [{q_text}]"
        )
        s = pose.singularity
        if self.site is None:
            self._measures.content = "*Singularity measures need an output site (the mechanism has none).*"
        elif s is None:
            self._measures.content = f"**Singularity measures** (site `{self.site}`): not assembled"
        else:
            flags = [n for n in ("type_I", "type_II", "constraint") if bool(getattr(s, n))]
            self._measures.content = (
                f"**Singularity measures** (site `{self.site}`, L = {_fmt(float(s.length))} m)\n\n"
                f"| | σ (m) | cond |\n|---|---|---|\n"
                f"| type I | {_fmt(float(s.sigma_I))} | {_fmt(float(s.cond_I))} |\n"
                f"| type II | {_fmt(float(s.sigma_II))} | {_fmt(float(s.cond_II))} |\n"
                f"| constraint | {_fmt(float(s.sigma_C))} | {_fmt(float(s.cond_C))} |\n\n"
                + (f'<span style="color:red">**singular: {", ".join(flags)}**</span>' if flags else "regular")
            )

    def _sync_sliders(self, q_act: NDArray[np.float64]) -> None:
        self._syncing = True
        try:
            for s, x in zip(self._sliders, q_act, strict=True):
                if np.isfinite(x):
                    s.value = float(np.clip(x, s.min, s.max))  # type: ignore[misc]
        finally:
            self._syncing = False

    def set_q_act(self, q_act: ArrayLike) -> Pose:
        """Assemble at the actuated coordinates ``q_act (n_act,)`` from the current pose and show it.

        The solve starts from the pose shown (the branch followed), in stages of at most
        ``STAGE_RAD`` (or ``STAGE_LENGTH_FRACTION`` of the characteristic length for a slide); a
        failed assembly is shown red with its residual, and the next solve starts again from the
        last assembled pose.  Returns the new :class:`Pose`.
        """
        qa = as_array(q_act, "q_act", (len(self.mech.actuated),))
        if qa.shape != (len(self.mech.actuated),):
            raise ValueError(f"Expected q_act to have shape ({len(self.mech.actuated)},), got {qa.shape}.")
        with self._lock:
            start = self._good  # the pose shown if it assembled, else the last assembled one
            delta = np.abs(qa - start[self._addr])
            scale = np.array(
                [STAGE_RAD if self.mech.joint(n).type == "hinge" else STAGE_LENGTH_FRACTION * self.mech.length
                 for n in self.mech.actuated]
            )  # fmt: skip
            ratio = float(np.max(delta / scale)) if delta.size and np.all(np.isfinite(delta)) else 1.0
            steps = int(min(MAX_STAGES, max(1, math.ceil(ratio))))
            fk = mb.forward_kinematics(self.mech, qa, start, steps=steps)
            pose = self._evaluate(
                fk.q, converged=bool(fk.converged), residual=float(fk.residual), note="slider"
            )
            self._commit(pose)
            self._sync_sliders(qa)
            return pose

    def set_q(self, q: ArrayLike) -> Pose:
        """Show the configuration ``q (nq,)`` as given (its closure residual is reported)."""
        qq = check_q(self.mech, q)
        if qq.ndim != 1:
            raise ValueError(f"Expected q to have shape ({self.mech.nq},), got {qq.shape}.")
        return self._show_q(qq, "configuration")

    def _show_q(self, q: NDArray[np.float64], note: str) -> Pose:
        """Show ``q``, assembled if its closure residual is within the solver's tolerance; a
        non-finite ``q`` (a simulation after its failure) is reported, the last pose kept drawn."""
        with self._lock:
            if np.all(np.isfinite(q)):
                res = float(np.max(np.abs(mb.constraint_residual(self.mech, q)), initial=0.0))
                ok = res <= mb.CONVERGED_RTOL * float(self.mech.tree.length)
            else:
                res, ok = float("nan"), False
            pose = self._evaluate(q, converged=ok, residual=res, note=note)
            self._commit(pose)
            self._sync_sliders(pose.q_act)
            return pose

    def _commit(self, pose: Pose) -> None:
        if pose.converged:
            self._good = pose.q
        self._show(pose)
        self.pose = pose

    # -- playback -------------------------------------------------------------------------------------
    def _show_frame(self, k: int) -> None:
        if self._path is None or self._syncing:
            return
        when = (
            f"t = {self._times[k]:.3f} s" if self._times is not None else f"frame {k + 1}/{len(self._path)}"
        )
        self._show_q(self._path[k], f"playback, {when}")

    def _toggle_play(self) -> None:
        if self._playing.is_set():
            self._playing.clear()
        else:
            self._playing.set()

    def _play_loop(self) -> None:
        while not self._closed.is_set():
            if not self._playing.wait(timeout=0.2) or self._frame_slider is None or self._path is None:
                continue
            k = (int(self._frame_slider.value) + 1) % self._path.shape[0]
            self._frame_slider.value = k  # type: ignore[misc]  # runs _show_frame (synchronously)
            time.sleep(1.0 / max(float(self._fps.value), 0.5))

    def play(self, playing: bool = True) -> None:
        """Start (or stop, ``playing=False``) the playback of the path given to :func:`view`."""
        if self._path is None:
            raise ValueError("Expected a path to play: pass path=(nt, nq) configurations to view().")
        (self._playing.set if playing else self._playing.clear)()

    # -- screenshots ----------------------------------------------------------------------------------
    def _on_screenshot(self, event: Any) -> None:
        client = event.client
        if client is None:
            return
        png = self._render_png(client, 720, 960)
        client.send_file_download(f"{self.mech.name}.png", png, save_immediately=True)

    @staticmethod
    def _render_png(client: Any, height: int, width: int) -> bytes:
        import imageio.v3 as iio  # a dependency of viser

        img = client.get_render(height, width, transport_format="png", timeout=SCREENSHOT_TIMEOUT)
        return bytes(iio.imwrite("<bytes>", img, extension=".png"))

    def screenshot(self, path: str | Path, *, width: int = 960, height: int = 720) -> Path:
        """Write a PNG of what a connected browser shows (raises ``RuntimeError`` if none is)."""
        width = check_int(width, "width", low=16, high=8192)
        height = check_int(height, "height", low=16, high=8192)
        clients = list(self._server.get_clients().values())
        if not clients:
            raise RuntimeError(f"No browser shows the viewer: open {self.url} first.")
        out = Path(path)
        out.write_bytes(self._render_png(clients[0], height, width))
        return out

    # -- lifetime -------------------------------------------------------------------------------------
    def stop(self) -> None:
        """Stop the server (the page disconnects); idempotent."""
        if self._closed.is_set():
            return
        self._closed.set()
        self._playing.clear()
        with contextlib.redirect_stdout(io.StringIO()):
            self._server.stop()

    @property
    def stopped(self) -> bool:
        """Whether :meth:`stop` was called."""
        return self._closed.is_set()

    def wait(self) -> None:
        """Block until :meth:`stop` is called or Ctrl-C (a script that shows a mechanism then waits)."""
        try:
            while not self._closed.wait(timeout=0.5):
                pass
        except KeyboardInterrupt:
            self.stop()

    def __repr__(self) -> str:
        state = "stopped" if self._closed.is_set() else self.url
        return f"<robomech Viewer of {self.mech.name!r} at {state}>"

    def _repr_html_(self) -> str:
        if self._closed.is_set():
            return f"<p>robomech viewer of {self.mech.name} (stopped)</p>"
        return (
            f'<iframe src="{self.url}" width="100%" height="560" style="border:0" '
            f'title="robomech viewer: {self.mech.name}"></iframe>'
        )


def view(
    mech: mb.Mechanism,
    q: ArrayLike | None = None,
    *,
    site: str | None = None,
    path: Any = None,
    times: ArrayLike | None = None,
    port: int | None = None,
    open_browser: bool = False,
    geometry: str | Path | None = None,
) -> Viewer:
    """Show ``mech`` in the browser: a live 3-D view with one slider per actuated joint.

    Parameters
    ----------
    mech : robomech.multibody.Mechanism
        The described mechanism.
    q : array_like, shape (nq,), optional
        Configuration shown first (default ``mech.q0``).
    site : str, optional
        Output site of the live singularity measures (default the first site; none without sites).
    path : array_like, shape (nt, nq), or robomech.multibody.SimulationResult, optional
        Configurations to play back (a frame slider and a play button), e.g. ``mb.simulate(...)``.
    times : array_like, shape (nt,), optional
        Time of each frame of ``path`` (s; taken from a ``SimulationResult``).
    port : int, optional
        TCP port on 127.0.0.1 (default a free one).
    open_browser : bool, optional
        Open the page in the default web browser.
    geometry : str or Path, optional
        An MJCF file whose geoms are drawn on the bodies of the same names (e.g. the file ``mech``
        was read from; needs MuJoCo); the links are then shown on request.

    Returns
    -------
    Viewer
        The running viewer: ``.url``, ``.pose``, ``.set_q_act``, ``.set_q``, ``.play``,
        ``.screenshot``, ``.stop()``; displayed inline in Jupyter.

    Notes
    -----
    Each slider move re-assembles the mechanism with :func:`robomech.multibody.forward_kinematics`
    from the pose shown (the branch followed); a pose that does not assemble turns the model red and
    the status says so with its residual.  Links are drawn between the points each body carries
    (joints, closure anchors, sites); a spherical linkage's links join points on its joint axes.
    The server binds 127.0.0.1 only.  Needs the ``view`` extra (``pip install 'robomech[view]'``).

    Examples
    --------
    >>> from robomech import multibody as mb
    >>> v = mb.view(mb.gallery.load("four_bar"))          # doctest: +SKIP
    >>> v.set_q_act([0.3]).converged                       # doctest: +SKIP
    True
    >>> v.stop()                                           # doctest: +SKIP
    """
    mech = check_mechanism(mech)
    q0 = check_q(mech, mech.q0 if q is None else q)
    if q0.ndim != 1:
        raise ValueError(f"Expected q to have shape ({mech.nq},) (one configuration), got {q0.shape}.")
    if site is None:
        site = mech.tree.site_names[0] if len(mech.tree.site_names) else None
    elif not isinstance(site, str) or site not in mech.tree.site_names:
        raise ValueError(f"Expected site to be None or one of {list(mech.tree.site_names)}, got {site!r}.")
    qs = tt = None
    if isinstance(path, mb.SimulationResult):
        qs, tt = np.asarray(path.q, float), np.asarray(path.t, float)
        if qs.ndim != 2:
            raise ValueError(f"Expected path to be one simulated motion (q (nt, nq)), got q {qs.shape}.")
    elif path is not None:
        # non-finite frames are allowed (a simulation after its failure): shown as not assembled
        qs = as_array(path, "path", (mech.nq,), finite=False)
        if qs.ndim != 2 or qs.shape[0] < 1:
            raise ValueError(f"Expected path to have shape (nt, {mech.nq}), got {qs.shape}.")
    if times is not None:
        if qs is None:
            raise ValueError("Expected times only with a path, got times without path.")
        tt = as_array(times, "times")
        if tt.shape != (qs.shape[0],):
            raise ValueError(
                f"Expected times to have shape ({qs.shape[0]},) (one per frame), got {tt.shape}."
            )
    if port is None:
        port = _free_port()
    port = check_int(port, "port", low=1, high=65535)
    if not isinstance(open_browser, bool):
        raise ValueError(f"Expected open_browser to be True or False, got {open_browser!r}.")
    geoms: tuple[Geom, ...] = ()
    if geometry is not None:
        if not isinstance(geometry, (str, Path)) or not Path(geometry).is_file():
            raise ValueError(f"Expected geometry to be None or an MJCF file, got {geometry!r}.")
        try:
            geoms = mjcf_geoms(geometry)
        except ValueError as exc:  # MuJoCo's compile error
            raise ValueError(f"Expected geometry to be an MJCF file MuJoCo reads, got {exc}") from exc
    viewer = Viewer(mech, np.asarray(q0, float), port=port, site=site, path=qs, times=tt, geoms=geoms)
    if open_browser:
        import webbrowser

        webbrowser.open(viewer.url)
    return viewer
