"""The viewer without a browser: what it draws, what a slider does, failures shown, playback, CLI.

The scene is checked against the multibody layer's own drawing data (`mb.body_segments`): placed at
any configuration, every link's ends are world points of that star.  A slider move is checked against
an independent call of `mb.forward_kinematics` from the pose shown, and the singularity measures
against `mb.singularities` at the pose.
"""

from __future__ import annotations

import socket
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from robomech import multibody as mb

pytest.importorskip("viser", reason="viser is not installed (pip install 'robomech[view]')")

from robomech.verify._generic import describe
from robomech.viewer import view
from robomech.viewer._scene import COINCIDENT_FRACTION, build_scene, poses
from robomech.viewer._server import FAILED_COLOUR

# Link ends and star points are the same points through the same body poses: they agree to
# rounding of a few 4x4 products (~1e-16 m on a 1 m mechanism); 1e-12 m leaves a margin.
POINT_TOL = 1e-12
# Two assemblies from the same start with the same solver agree to the solver's stopping tolerance.
Q_TOL = 1e-10
# The CLI's bound on a start-and-fail (imports + a usage error), s.
CLI_TIMEOUT = 120


def _world(T, b, x):
    return T[b, :3, :3] @ x + T[b, :3, 3]


@pytest.mark.parametrize("name", ["four_bar", "delta", "stewart", "planar_3rrr"])
def test_links_are_the_wireframe_at_any_pose(name):
    mech = mb.gallery.load(name)
    scene = build_scene(mech)
    qa0 = mech.q0[[mech.qpos_address(j) for j in mech.actuated]]
    q = mb.forward_kinematics(mech, qa0 + 0.1, mech.q0).q
    T = poses(mech, q)
    star = [s.reshape(-1, 3) for s in mb.body_segments(mech, q).values()]
    # a slider is drawn from the fixed end of its stroke (on its parent), where the star has the
    # moving anchor: those ends are the parent's pose times the child's offset at zero stroke
    tree = mech.tree
    for i, body in enumerate(mech.bodies, start=1):
        if body.joints and body.joints[0].type == "slide":
            held = T[int(tree.parent[i])] @ tree.T_off[i]
            star.append((held[:3, :3] @ np.asarray(body.joints[0].pos) + held[:3, 3])[None])
    points = np.concatenate(star)
    ends = np.array([_world(T, link.body, p) for link in scene.links for p in (link.a, link.b)])
    d = np.min(np.linalg.norm(ends[:, None] - points[None], axis=-1), axis=1)
    assert np.max(d) < POINT_TOL
    assert all(np.linalg.norm(link.b - link.a) > COINCIDENT_FRACTION * mech.length for link in scene.links)


@pytest.mark.parametrize("name", ["vectored-thrust", "spherical-leg"])
def test_a_spherical_mechanism_is_drawn_with_visible_links(name):
    mech = describe(name)
    segments = mb.body_segments(mech, mech.q0)
    lengths = np.concatenate([np.linalg.norm(s[:, 1] - s[:, 0], axis=-1) for s in segments.values()])
    scene = build_scene(mech)
    drawn = np.array([np.linalg.norm(link.b - link.a) for link in scene.links])
    # the wireframe has coincident ends (the joints meet at the centre); the viewer draws every link
    assert np.sum(lengths < COINCIDENT_FRACTION * mech.length) >= 1 or name == "spherical-leg"
    assert drawn.size >= len(mech.bodies) and np.all(drawn > COINCIDENT_FRACTION * mech.length)


@pytest.fixture()
def delta_viewer():
    v = view(mb.gallery.load("delta"))
    yield v
    v.stop()


def test_a_slider_move_reassembles_from_the_pose_shown(delta_viewer):
    v, mech = delta_viewer, delta_viewer.mech
    start = v.pose.q.copy()
    target = v.pose.q_act + np.array([0.3, -0.2, 0.1])
    pose = v.set_q_act(target)
    assert pose.converged and "assembled" in pose.status
    assert not np.allclose(pose.q, start)
    np.testing.assert_allclose(pose.q_act, target, atol=Q_TOL)
    # the branch followed: in stages from the pose shown (as the viewer does: 6 stages of <= 0.05 rad)
    ref = mb.forward_kinematics(mech, target, start, steps=6)
    np.testing.assert_allclose(pose.q, ref.q, atol=Q_TOL)
    s = mb.singularities(mech, pose.q, "tcp")
    assert float(pose.singularity.sigma_II) == pytest.approx(float(s.sigma_II), rel=1e-12)
    assert [float(x.value) for x in v._sliders] == pytest.approx(list(target))
    assert "σ" in v._measures.content and f"{float(s.sigma_I):.4g}" in v._measures.content


def test_a_failed_assembly_is_shown_red_and_recovers():
    v = view(mb.gallery.load("rps_3"))
    try:
        good = v.pose.q.copy()
        pose = v.set_q_act(v.pose.q_act + np.array([0.5, -0.5, -0.5]))
        assert not pose.converged and pose.residual > 1e-3
        assert "did not assemble: residual" in pose.status and "did not assemble" in v._status.content
        assert all(node.color == FAILED_COLOUR for node, _ in v._nodes)
        back = v.set_q_act(good[[v.mech.qpos_address(j) for j in v.mech.actuated]])
        assert back.converged and all(node.color == c for node, c in v._nodes)
        np.testing.assert_allclose(back.q, good, atol=1e-8)
    finally:
        v.stop()


def test_playback_of_a_simulation():
    mech = mb.gallery.load("four_bar")
    qa = np.linspace(0.2, 1.0, 5)[:, None]
    path = mb.forward_kinematics(mech, qa).q
    v = view(mech, path=path, times=np.arange(5) * 0.1)
    try:
        v._frame_slider.value = 3  # what the frame slider or the play button does
        np.testing.assert_allclose(v.pose.q, path[3])
        assert v.pose.converged and "t = 0.300 s" in v.pose.status
        bad = path.copy()
        bad[2] = np.nan  # a simulation after its failure
        v2 = view(mech, path=bad)
        try:
            v2._frame_slider.value = 2
            assert not v2.pose.converged and np.isnan(v2.pose.residual)
        finally:
            v2.stop()
    finally:
        v.stop()


def test_the_server_binds_localhost_only_and_stops(delta_viewer):
    v = delta_viewer
    assert v.url == f"http://127.0.0.1:{v.port}"
    assert 'iframe src="http://127.0.0.1:' in v._repr_html_()
    with socket.create_connection(("127.0.0.1", v.port), timeout=5):
        pass
    v.stop()
    assert v.stopped and "stopped" in repr(v)
    other = view(mb.gallery.load("four_bar"))
    try:
        with pytest.raises(RuntimeError, match="No browser"):
            other.screenshot(Path("never.png"))
    finally:
        other.stop()


def test_mb_view_is_the_viewer():
    v = mb.view(mb.gallery.load("four_bar"), site="coupler_point")
    try:
        assert v.site == "coupler_point" and v.pose.converged
    finally:
        v.stop()


def test_cli_rejects_bad_input_with_exit_2(tmp_path):
    src = str(Path(__file__).resolve().parents[2] / "src")
    env = {"PYTHONPATH": src, "PATH": "/usr/bin:/bin", "HOME": str(Path.home())}
    for argv, needle in (
        (["view", "no-such-mechanism", "--no-browser"], "Expected MECHANISM"),
        (["view", "delta", "--port", "0", "--no-browser"], "--port"),
        (["view", "delta", "--site", "nope", "--no-browser"], "Expected site"),
        *([(["view", "robot.urdf", "--no-browser"], "URDF")] if not hasattr(mb, "from_urdf") else []),
    ):
        r = subprocess.run(
            [sys.executable, "-m", "robomech", *argv],
            capture_output=True, text=True, timeout=CLI_TIMEOUT, env=env, cwd=tmp_path,
        )  # fmt: skip
        assert r.returncode == 2, (argv, r.stdout, r.stderr)
        assert needle in r.stderr and "Traceback" not in r.stderr


def test_the_viewer_methods_validate_their_input(delta_viewer):
    v = delta_viewer
    for bad in (np.zeros(2), np.zeros((2, 3)), "x", [np.nan, 0.0, 0.0]):
        with pytest.raises(ValueError, match="q_act"):
            v.set_q_act(bad)
    with pytest.raises(ValueError, match="q"):
        v.set_q(np.zeros(3))
    with pytest.raises(ValueError, match="width"):
        v.screenshot("x.png", width=0)
    with pytest.raises(ValueError, match="path to play"):
        v.play()


@pytest.mark.parametrize("name", ["delta", "stewart"])
def test_mjcf_geoms_sit_where_mujoco_puts_them(name):
    """The geoms hang on the description's body frames: placed at an assembled pose, their centres
    are MuJoCo's own geom_xpos after mj_kinematics at the same qpos (an independent engine)."""
    mujoco = pytest.importorskip("mujoco")
    from robomech.viewer._geoms import mjcf_geoms

    mech = mb.gallery.load(name)
    path = mb.gallery.path(name)
    geoms = mjcf_geoms(path)
    qa0 = mech.q0[[mech.qpos_address(j) for j in mech.actuated]]
    q = mb.forward_kinematics(mech, qa0 + 0.05, mech.q0).q
    T = poses(mech, q)
    index = {n: b for b, n in enumerate(mech.tree.body_names)}
    ours = np.array([_world(T, index[g.body], g.pos) for g in geoms])
    model = mujoco.MjModel.from_xml_path(str(path))
    data = mujoco.MjData(model)
    data.qpos[:] = q
    mujoco.mj_kinematics(model, data)
    drawn = [g for g in range(model.ngeom) if int(model.geom_type[g]) in (2, 3, 4, 5, 6, 7)]
    np.testing.assert_allclose(ours, data.geom_xpos[drawn], atol=POINT_TOL)
    v = view(mech, geometry=path)
    try:
        assert len(v._geom_nodes) == len(geoms) and all(not n.visible for n in v._links)
    finally:
        v.stop()
    with pytest.raises(ValueError, match="geometry"):
        view(mech, geometry="no-such-file.xml")


def test_cli_motion_and_simulation_become_the_playback(tmp_path):
    import argparse

    from robomech.cli.view import _motion

    mech = mb.gallery.load("four_bar")
    q = mb.forward_kinematics(mech, np.linspace(0.2, 1.0, 4)[:, None]).q
    np.savez(tmp_path / "m.npz", q=q, t=np.arange(4) * 0.5)
    np.save(tmp_path / "m.npy", q)
    none = {"motion": None, "simulate": None}
    path, times = _motion(argparse.Namespace(**{**none, "motion": str(tmp_path / "m.npz")}), mech)
    np.testing.assert_array_equal(path, q)
    np.testing.assert_array_equal(times, np.arange(4) * 0.5)
    path, times = _motion(argparse.Namespace(**{**none, "motion": str(tmp_path / "m.npy")}), mech)
    np.testing.assert_array_equal(path, q)
    assert times is None
    sim, _ = _motion(argparse.Namespace(**{**none, "simulate": 0.1}), mech)
    assert isinstance(sim, mb.SimulationResult) and sim.q.shape == (4, mech.nq) and bool(sim.success)
    v = view(mech, path=sim)
    try:
        v._frame_slider.value = 3
        np.testing.assert_allclose(v.pose.q, sim.q[3])
    finally:
        v.stop()
    src = str(Path(__file__).resolve().parents[2] / "src")
    env = {"PYTHONPATH": src, "PATH": "/usr/bin:/bin", "HOME": str(Path.home())}
    r = subprocess.run(
        [sys.executable, "-m", "robomech", "view", "four_bar", "--no-browser", "--motion", "missing.npy"],
        capture_output=True, text=True, timeout=CLI_TIMEOUT, env=env, cwd=tmp_path,
    )  # fmt: skip
    assert r.returncode == 2 and "--motion" in r.stderr and "Traceback" not in r.stderr
