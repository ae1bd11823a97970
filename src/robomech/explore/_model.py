"""A design study of any described mechanism: a parametrized description, variables, a task, metrics.

The description is ``build(**params) -> Mechanism`` (the multibody :class:`~robomech.multibody.Builder`,
or :func:`~robomech.multibody.from_mjcf` of text the function formats), or an MJCF/URDF template file
whose numbers are named parameters (``{L1}`` or ``$L1``, :func:`template_builder`).  Each design is one
call of ``build``; the generic metrics are computed by the engine's public API
(:func:`~robomech.multibody.inverse_kinematics`, :func:`~robomech.multibody.site_jacobian`,
:func:`~robomech.multibody.singularities`, :func:`~robomech.multibody.forward_kinematics`,
:func:`~robomech.multibody.inverse_dynamics`) on the study's task, one batched call per design.
A design whose ``build`` raises, or whose mechanism the engine refuses, is a failed design
(``design_ok`` False, metrics NaN), never an exception.  Definitions: :data:`GENERIC_METRICS` and
``docs/explore.md``.
"""

from __future__ import annotations

import importlib.util
import inspect
import math
import string
import sys
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from robomech._validation import as_array, check_int, check_positive

from ._study import DesignStudy, Metric, Objective, Variable, check_variables

__all__ = ["GENERIC_METRICS", "ModelStudy", "UserMetric", "load_model", "model_study", "template_builder"]

AXES = "xyz"

# name -> (unit template, description, what the study must define); "{L}" is the task's length unit
# to the power of its number of output axes, "{F}" the actuators' force unit.
GENERIC_METRICS: dict[str, tuple[str, str, str]] = {
    "workspace_measure": (
        "{L}",
        "reachable workspace measure: (task points the site reaches) x (task cell measure); an area "
        "(m^2) for two output axes, a volume (m^3) for three",
        "task_box",
    ),
    "task_fraction": ("", "fraction of the task points the site reaches (IK converged)", "task"),
    "dexterity_min": (
        "",
        "min over the reached task points of the inverse condition number sigma_min / sigma_max of "
        "the output rows of the site Jacobian, hinge columns divided by the characteristic length",
        "task",
    ),
    "dexterity_mean": ("", "mean of the same inverse condition number over the reached task points", "task"),
    "type2_distance": (
        "m",
        "min over the reached task points of sigma_II, the relevant smallest singular value of the "
        "passive constraint block (0 at a type II singularity; multibody.singularities)",
        "task",
    ),
    "constraint_distance": (
        "m",
        "min over the reached task points of sigma_C, the rank-th singular value of the constraint "
        "Jacobian (0 at a constraint singularity; multibody.singularities)",
        "task",
    ),
    "assembly_failure": (
        "",
        "fraction of the actuator-box grid where forward kinematics does not converge",
        "input_box",
    ),
    "peak_force": (
        "{F}",
        "max over the trajectory and the actuators of |tau| (IK along the trajectory, rates by "
        "finite differences in time, multibody.inverse_dynamics with gravity)",
        "trajectory",
    ),
    "rms_force": ("{F}", "RMS over the trajectory samples and the actuators of tau", "trajectory"),
}


@dataclass(frozen=True)
class UserMetric:
    """A metric computed by the user's function ``fn(mech, params) -> float``.

    Parameters
    ----------
    name : str
        A Python identifier, distinct from the generic metrics' names.
    fn : callable
        ``fn(mech, params)`` with ``mech`` the design's Mechanism and ``params`` its dict of variable
        values; returns a float (NaN, or an exception, makes that design's value NaN).
    unit : str, optional
        Unit label.
    description : str, optional
        Its definition, for reports.

    Raises
    ------
    ValueError
        If ``name`` is not an identifier or is a generic metric's name, ``fn`` is not callable, or
        ``unit`` / ``description`` are not str.
    """

    name: str
    fn: Callable[[Any, dict[str, float]], float]
    unit: str = ""
    description: str = ""

    def __post_init__(self) -> None:
        if not isinstance(self.name, str) or not self.name.isidentifier() or self.name in GENERIC_METRICS:
            raise ValueError(
                f"Expected name to be an identifier other than the generic metrics, got {self.name!r}."
            )
        if not callable(self.fn):
            raise ValueError(f"Expected fn to be callable, got {type(self.fn).__name__}.")
        for n in ("unit", "description"):
            if not isinstance(getattr(self, n), str):
                raise ValueError(f"Expected {n} to be a str, got {type(getattr(self, n)).__name__}.")


def _nominal() -> None:
    return None


@dataclass(frozen=True)
class ModelStudy(DesignStudy):
    """A :class:`DesignStudy` of a user's parametrized mechanism (made by :func:`model_study`).

    Each design row is passed to ``build`` as keyword arguments; ``evaluate`` computes the generic
    metrics of :data:`GENERIC_METRICS` it was given and the user metrics.  Runs through
    :func:`run_sweep` and :func:`optimize_nsga2` like the built-in studies.

    Attributes
    ----------
    build : callable
        ``build(**params) -> Mechanism``, the parametrized description.
    site : str
        The output site of the task and workspace metrics.
    outputs : str
        The site's position axes the task is stated in (``"xy"``, ``"xyz"``, ...).
    task, box, grid
        Task points ``(m, 3)`` (m), or a task box ``(k, 2)`` over the output axes (m) sampled on
        ``grid`` cells per axis.
    input_box, input_grid
        The actuator box ``(n_act, 2)`` and its cells per axis, for the assembly-failure metric.
    trajectory : tuple of ndarray, optional
        Times ``(T,)`` (s) and site points ``(T, 3)`` (m) of the task the actuator forces are taken along.
    length : float, optional
        Characteristic length (m) dividing hinge columns in the dexterity (default the mechanism's).
    user_metrics : tuple of UserMetric
        Metrics given as Python callables.
    generic : tuple of str
        The generic metrics computed (names in :data:`GENERIC_METRICS`).
    """

    build: Callable[..., Any] = _nominal
    site: str = ""
    outputs: str = "xy"
    task: np.ndarray | None = None  # (m, 3) task points (m)
    box: np.ndarray | None = None  # (k, 2) task box over the output axes (m)
    grid: int = 32  # cells per axis of the task box
    input_box: np.ndarray | None = None  # (n_act, 2)
    input_grid: int = 8
    trajectory: tuple[np.ndarray, np.ndarray] | None = None  # times (T,), points (T, 3)
    length: float | None = None
    user_metrics: tuple[UserMetric, ...] = ()
    generic: tuple[str, ...] = field(default=())

    def parameter_fields(self) -> tuple[str, ...]:
        """The variable names ``build`` accepts (its keyword parameters)."""
        return build_parameters(self.build)

    def designs_to_params(self, rows: np.ndarray) -> list[Any]:
        """``{variable: value}`` per row (None for a row with a non-finite value)."""
        names = self.variable_names
        out: list[Any] = []
        for row in np.asarray(rows, dtype=float):
            out.append(
                {n: float(x) for n, x in zip(names, row, strict=True)} if np.all(np.isfinite(row)) else None
            )
        return out


def build_parameters(build: Callable[..., Any]) -> tuple[str, ...]:
    """Names of the keyword parameters of ``build`` (all of them if it takes ``**params``: ())."""
    try:
        sig = inspect.signature(build)
    except (TypeError, ValueError):
        return ()
    return tuple(
        p.name
        for p in sig.parameters.values()
        if p.kind in (inspect.Parameter.POSITIONAL_OR_KEYWORD, inspect.Parameter.KEYWORD_ONLY)
    )


def _takes_any(build: Callable[..., Any]) -> bool:
    try:
        sig = inspect.signature(build)
    except (TypeError, ValueError):
        return True
    return any(p.kind is inspect.Parameter.VAR_KEYWORD for p in sig.parameters.values())


def task_grid(box: np.ndarray, n: int, outputs: str, z0: np.ndarray) -> tuple[np.ndarray, float]:
    """Cell-centre points ``(n**k, 3)`` of the box ``(k, 2)`` over the output axes, and one cell's measure.

    The coordinates that are not outputs are those of ``z0`` (the site's reference position)."""
    k = len(outputs)
    h = (box[:, 1] - box[:, 0]) / n
    axes = [box[i, 0] + (np.arange(n) + 0.5) * h[i] for i in range(k)]
    grid = np.stack(np.meshgrid(*axes, indexing="ij"), -1).reshape(-1, k)
    pts = np.broadcast_to(z0, (grid.shape[0], 3)).copy()
    for i, a in enumerate(outputs):
        pts[:, AXES.index(a)] = grid[:, i]
    return pts, float(np.prod(h))


def model_study(
    build: Callable[..., Any],
    variables: Sequence[Variable],
    *,
    site: str,
    metrics: Sequence[str] = ("workspace_measure", "task_fraction", "dexterity_min", "dexterity_mean"),
    outputs: str = "xy",
    task_box: Any = None,
    task_grid_size: int = 32,
    task_points: Any = None,
    input_box: Any = None,
    input_grid: int = 8,
    trajectory: Any = None,
    user_metrics: Sequence[UserMetric] = (),
    objectives: Sequence[Objective] = (),
    length: float | None = None,
    name: str = "model",
    chunk: int = 8,
) -> ModelStudy:
    """A design study of the mechanism ``build(**params)`` over ``variables``.

    Parameters
    ----------
    build : callable
        ``build(**params) -> Mechanism``; every variable is passed as a keyword (SI units).  A design
        for which it raises is a failed design.  For a sweep on other processes it must be picklable
        (a module-level function; :func:`load_model` arranges that for a file).
    variables : sequence of Variable
        Range variables (``kind="range"``), each a keyword parameter of ``build``; distinct names.
    site : str
        The output site of the mechanism (its position is the task's output).
    metrics : sequence of str, optional
        Names from :data:`GENERIC_METRICS` (each needs what its entry says: a task box, a task, an
        actuator box or a trajectory).
    outputs : str, optional
        The output axes of the task, a subset of ``"xyz"`` in order (default ``"xy"``, planar); the
        IK leaves the other coordinates and the orientation free.
    task_box : array_like, shape (k, 2), optional
        ``[[lo, hi], ...]`` per output axis (m): the task is the grid of its cell centres,
        ``task_grid_size`` per axis.  Needed by ``workspace_measure``.
    task_grid_size : int, optional
        Cells per axis of the task box (>= 2; default 32).
    task_points : array_like, shape (m, 3), optional
        A task of explicit site positions (m) instead of a box.
    input_box : array_like, shape (n_act, 2), optional
        Actuator ranges (rad or m) for ``assembly_failure``, sampled on ``input_grid`` points per axis.
    input_grid : int, optional
        Points per actuator axis (>= 2; default 8).
    trajectory : tuple (t, points), optional
        Times ``t (T,)`` (s, increasing, T >= 3) and site positions ``points (T, 3)`` (m) for
        ``peak_force`` / ``rms_force``.
    user_metrics : sequence of UserMetric, optional
        Metrics computed by the user's functions.
    objectives : sequence of Objective, optional
        For the Pareto front and NSGA-II.
    length : float, optional
        Characteristic length (m) for the dexterity's hinge columns; default each design's
        ``mech.length``.
    name : str, optional
        The study's name (stored in the results).
    chunk : int, optional
        Designs per Dask task (>= 1; default 8).

    Returns
    -------
    ModelStudy

    Raises
    ------
    ValueError
        If ``build`` is not callable, a variable is not a range variable or names no parameter of
        ``build``, a metric is unknown or lacks what it needs, or a box, task or trajectory has the
        wrong shape or is not finite.

    Examples
    --------
    >>> from robomech.explore import Variable, model_study
    >>> from robomech.multibody import gallery
    >>> st = model_study(lambda: gallery.load("four_bar"), [], site="coupler_point")  # doctest: +SKIP
    """
    if not callable(build):
        raise ValueError(f"Expected build to be callable, got {type(build).__name__}.")
    variables = check_variables(variables)
    if not variables:
        raise ValueError("Expected variables to hold at least one design variable, got none.")
    names = [v.name for v in variables]
    if len(set(names)) != len(names):
        raise ValueError(f"Expected variables with distinct names, got {names}.")
    params = build.names if isinstance(build, _Template) else build_parameters(build)
    for v in variables:
        if v.kind != "range":
            raise ValueError(f"Expected range variables (NAME=LO:HI), got {v.name!r} of kind {v.kind!r}.")
        if (isinstance(build, _Template) or not _takes_any(build)) and v.name not in params:
            raise ValueError(
                f"Expected variables to name parameters of build ({', '.join(params) or 'none'}), "
                f"got {v.name!r}."
            )
    if not isinstance(site, str) or not site:
        raise ValueError(f"Expected site to be a site name (str), got {site!r}.")
    if not isinstance(outputs, str) or not outputs or any(a not in AXES for a in outputs):
        raise ValueError(f"Expected outputs to be a subset of 'xyz' such as 'xy', got {outputs!r}.")
    if len(set(outputs)) != len(outputs) or "".join(sorted(outputs)) != outputs:
        raise ValueError(f"Expected outputs to be distinct axes in order (e.g. 'xz'), got {outputs!r}.")
    if isinstance(metrics, str) or not isinstance(metrics, Sequence):
        raise ValueError(f"Expected metrics to be a sequence of metric names, got {metrics!r}.")
    metrics = tuple(metrics)
    for m in metrics:
        if m not in GENERIC_METRICS:
            raise ValueError(f"Expected metrics among {', '.join(GENERIC_METRICS)}, got {m!r}.")
    if len(set(metrics)) != len(metrics):
        raise ValueError(f"Expected each metric once, got {list(metrics)}.")
    user_metrics = tuple(user_metrics)
    if not all(isinstance(u, UserMetric) for u in user_metrics):
        raise ValueError("Expected user_metrics to be a sequence of UserMetric.")
    if not metrics and not user_metrics:
        raise ValueError("Expected metrics or user_metrics to hold at least one metric, got none.")
    k = len(outputs)
    n_grid = check_int(task_grid_size, "task_grid_size", low=2, high=4096)
    box = None
    if task_box is not None:
        box = as_array(task_box, "task_box", (k, 2))
        if box.shape != (k, 2) or not np.all(box[:, 0] < box[:, 1]):
            raise ValueError(
                f"Expected task_box of shape ({k}, 2) with lo < hi per axis, got {box.tolist()}."
            )
        if n_grid**k > 10**6:
            raise ValueError(f"Expected at most 10^6 task points, got task_grid_size {n_grid} ** {k}.")
    pts = None
    if task_points is not None:
        if box is not None:
            raise ValueError("Expected task_box or task_points, got both.")
        pts = as_array(task_points, "task_points", (3,))
        if pts.ndim != 2 or pts.shape[0] < 1:
            raise ValueError(f"Expected task_points of shape (m, 3), got {pts.shape}.")
    ibox = None
    if input_box is not None:
        ibox = as_array(input_box, "input_box", (2,))
        if ibox.ndim != 2 or not np.all(ibox[:, 0] < ibox[:, 1]):
            raise ValueError(f"Expected input_box of shape (n_act, 2) with lo < hi, got {ibox.tolist()}.")
    n_in = check_int(input_grid, "input_grid", low=2, high=1024)
    traj = None
    if trajectory is not None:
        if not isinstance(trajectory, tuple | list) or len(trajectory) != 2:
            raise ValueError("Expected trajectory to be a pair (t (T,), points (T, 3)).")
        t = as_array(trajectory[0], "trajectory[0]", ())
        p = as_array(trajectory[1], "trajectory[1]", (3,))
        if t.ndim != 1 or t.size < 3 or not np.all(np.diff(t) > 0) or p.shape != (t.size, 3):
            raise ValueError(
                f"Expected trajectory times (T,) increasing with T >= 3 and points (T, 3), got "
                f"{t.shape} and {p.shape}."
            )
        traj = (t, p)
    L = None if length is None else check_positive(length, "length")
    for m in metrics:
        need = GENERIC_METRICS[m][2]
        have = {
            "task_box": box is not None,
            "task": box is not None or pts is not None,
            "input_box": ibox is not None,
            "trajectory": traj is not None,
        }[need]
        if not have:
            raise ValueError(f"Expected a {need.replace('_', ' ')} for metric {m!r}, got none.")
    # the study's metrics: units from the first design would be late; force unit from the actuators
    length_unit = "m" if k == 1 else f"m^{k}"
    metric_objs = [
        Metric(
            m,
            GENERIC_METRICS[m][0].replace("{L}", length_unit).replace("{F}", "N or N m"),
            GENERIC_METRICS[m][1],
        )
        for m in metrics
    ]
    metric_objs += [Metric(u.name, u.unit, u.description) for u in user_metrics]
    n_task = n_grid**k if box is not None else (pts.shape[0] if pts is not None else 0)
    poses = max(
        1, n_task + (n_in ** ibox.shape[0] if ibox is not None else 0) + (traj[0].size if traj else 0)
    )
    parameters = {
        "site": site,
        "outputs": outputs,
        "task_box": None if box is None else box.tolist(),
        "task_grid": n_grid if box is not None else None,
        "task_points": None if pts is None else int(pts.shape[0]),
        "input_box": None if ibox is None else ibox.tolist(),
        "input_grid": n_in if ibox is not None else None,
        "trajectory_samples": None if traj is None else int(traj[0].size),
        "length": L,
        "build": getattr(build, "__qualname__", type(build).__name__),
    }
    return ModelStudy(
        name=name,
        title=f"Design study {name} ({parameters['build']})",
        mechanism="multibody",
        nominal=_nominal,
        variables=variables,
        metrics=tuple(metric_objs),
        evaluate=_evaluate,
        parameters=parameters,
        objectives=tuple(objectives),
        poses_per_design=poses,
        default_sampler="sobol",
        default_chunk=check_int(chunk, "chunk", low=1),
        default_designs=64,
        build=build,
        site=site,
        outputs=outputs,
        task=pts,
        box=box,
        grid=n_grid,
        input_box=ibox,
        input_grid=n_in,
        trajectory=traj,
        length=L,
        user_metrics=user_metrics,
        generic=metrics,
        error_names=(),
    )


def _task_of(study: ModelStudy, mech: Any) -> tuple[np.ndarray, float]:
    """The task points of one design (a box's grid is placed at the site's reference off-axis position)."""
    from robomech import multibody as mb

    if study.box is None:
        return np.asarray(study.task), math.nan
    z0 = mb.site_pose(mech, mech.q0, study.site)[:3, 3]
    return task_grid(np.asarray(study.box), study.grid, study.outputs, z0)


def _weights(outputs: str) -> np.ndarray:
    w = np.zeros(6)
    for a in outputs:
        w[3 + AXES.index(a)] = 1.0
    return w


def _targets(points: np.ndarray) -> np.ndarray:
    T = np.broadcast_to(np.eye(4), (points.shape[0], 4, 4)).copy()
    T[:, :3, 3] = points
    return T


def _one_design(study: ModelStudy, params: dict[str, float]) -> dict[str, float]:
    """Every metric of one design (raises if the design cannot be built: the caller marks it failed)."""
    from robomech import multibody as mb

    mech = study.build(**params)
    if not isinstance(mech, mb.Mechanism):
        raise TypeError(f"build returned {type(mech).__name__}, not a Mechanism")
    mech.site(study.site)  # a design without the site fails here
    out: dict[str, float] = {}
    gen = set(study.generic)
    if gen & {
        "workspace_measure",
        "task_fraction",
        "dexterity_min",
        "dexterity_mean",
        "type2_distance",
        "constraint_distance",
    }:
        pts, cell = _task_of(study, mech)
        radius = (
            None
            if study.box is None
            else RETRY_CELLS * float(np.max(np.diff(study.box, axis=1))) / study.grid
        )
        q, ok = reach(mech, study.site, pts, study.outputs, radius)
        reached = int(ok.sum())
        out["workspace_measure"] = reached * cell
        out["task_fraction"] = reached / pts.shape[0]
        if gen & {"dexterity_min", "dexterity_mean"}:
            inv = dexterity(mech, q[ok], study.site, study.outputs, study.length)
            out["dexterity_min"] = float(inv.min()) if inv.size else math.nan
            out["dexterity_mean"] = float(inv.mean()) if inv.size else math.nan
        if gen & {"type2_distance", "constraint_distance"}:
            if reached:
                s = mb.singularities(mech, q[ok], study.site, length=study.length)
                out["type2_distance"] = float(np.min(s.sigma_II))
                out["constraint_distance"] = float(np.min(s.sigma_C))
            else:
                out["type2_distance"] = out["constraint_distance"] = math.nan
    if "assembly_failure" in gen:
        box = np.asarray(study.input_box)
        if box.shape[0] != len(mech.actuated):
            raise ValueError(
                f"input_box has {box.shape[0]} rows, the mechanism {len(mech.actuated)} actuators"
            )
        axes = [np.linspace(lo, hi, study.input_grid) for lo, hi in box]
        qa = np.stack(np.meshgrid(*axes, indexing="ij"), -1).reshape(-1, box.shape[0])
        fk = mb.forward_kinematics(mech, qa)
        out["assembly_failure"] = float(1.0 - np.mean(np.asarray(fk.converged, bool)))
    if gen & {"peak_force", "rms_force"} and study.trajectory is not None:
        out["peak_force"], out["rms_force"] = task_forces(mech, study.site, study.outputs, study.trajectory)
    for u in study.user_metrics:
        try:
            out[u.name] = float(u.fn(mech, dict(params)))
        except Exception:  # a user metric failing on one design: NaN for that design only
            out[u.name] = math.nan
    return out


# Rounds of re-solving the task points the IK missed from their nearest reached neighbour's configuration.
IK_RETRIES = 2
# On a task grid, re-solve only the missed points within this many cells of a reached one (1.5: the
# eight neighbours of a cell).
RETRY_CELLS = 1.5
# Continuation stages of such a re-solve (the neighbour's pose is one task cell or more away).
IK_RETRY_STEPS = 4


def reach(
    mech: Any, site: str, pts: np.ndarray, outputs: str, radius: float | None = None
) -> tuple[np.ndarray, np.ndarray]:
    """Configurations ``q (m, nq)`` placing ``site`` at the task points ``pts (m, 3)`` along ``outputs``,
    and which converged ``(m,)``.

    One batched :func:`~robomech.multibody.inverse_kinematics` from ``mech.q0``, then up to
    ``IK_RETRIES`` rounds re-solving each missed point from the configuration of the nearest reached
    point (continuation in ``IK_RETRY_STEPS`` stages): the IK is a local solver, and a reachable point far
    from the reference configuration can be missed from ``q0`` alone.  With ``radius`` (m) only the
    missed points within ``radius`` of a reached one are re-solved (on a task grid, the cells next to
    the reached region: each round grows it by one cell).
    """
    from robomech import multibody as mb

    w = _weights(outputs)
    T = _targets(pts)
    ik = mb.inverse_kinematics(mech, site, T, weights=w)
    q = np.array(ik.q)
    ok = np.asarray(ik.converged, bool).copy()
    for _ in range(IK_RETRIES):
        miss = np.flatnonzero(~ok)
        if miss.size == 0 or not ok.any():
            break
        have = np.flatnonzero(ok)
        d = np.linalg.norm(pts[miss, None, :] - pts[None, have, :], axis=-1)
        near = np.argmin(d, axis=1)
        if radius is not None:
            keep = d[np.arange(miss.size), near] <= radius
            miss, near = miss[keep], near[keep]
            if miss.size == 0:
                break
        guess = q[have[near]]
        again = mb.inverse_kinematics(mech, site, T[miss], guess, weights=w, steps=IK_RETRY_STEPS)
        got = np.asarray(again.converged, bool)
        if not got.any():
            break
        q[miss[got]] = again.q[got]
        ok[miss[got]] = True
    return q, ok


def dexterity(mech: Any, q: np.ndarray, site: str, outputs: str, length: float | None = None) -> np.ndarray:
    """Inverse condition numbers ``sigma_min / sigma_max (m,)`` of the scaled output Jacobian at ``q``.

    The rows are the site's linear velocity along ``outputs`` (m/s); each hinge actuator's column is
    divided by the characteristic length L (``length``, default ``mech.length``) so that every entry is
    dimensionless (a slide's column is m/m already).  1 is isotropic, 0 singular.
    """
    from robomech import multibody as mb

    if q.shape[0] == 0:
        return np.zeros(0)
    J = mb.site_jacobian(mech, q, site)
    rows = [3 + AXES.index(a) for a in outputs]
    L = mech.length if length is None else length
    scale = np.array([1.0 / L if mech.joint(j).type == "hinge" else 1.0 for j in mech.actuated])
    s = np.linalg.svd(J[:, rows, :] * scale, compute_uv=False)
    return np.where(s[:, 0] > 0, s[:, -1] / np.where(s[:, 0] > 0, s[:, 0], 1.0), 0.0)


def task_forces(
    mech: Any, site: str, outputs: str, trajectory: tuple[np.ndarray, np.ndarray]
) -> tuple[float, float]:
    """Peak and RMS actuator force along ``trajectory = (t, points)``: IK with the previous solution as
    the guess, actuator rates by second-order finite differences in time (``numpy.gradient``), then
    inverse dynamics with gravity; NaN if any sample fails (not reached, singular, not valid)."""
    from robomech import multibody as mb

    t, pts = trajectory
    T = _targets(pts)
    w = _weights(outputs)
    guess = mech.q0
    qs = []
    for i in range(t.size):
        ik = mb.inverse_kinematics(mech, site, T[i], guess, weights=w, steps=4 if i == 0 else 1)
        if not bool(ik.converged):
            return math.nan, math.nan
        qs.append(ik.q)
        guess = ik.q
    q = np.stack(qs)
    qa = q[:, [mech.qpos_address(j) for j in mech.actuated]]
    qd = np.gradient(qa, t, axis=0, edge_order=2)
    qdd = np.gradient(qd, t, axis=0, edge_order=2)
    res = mb.inverse_dynamics(mech, q, qd, qdd)
    if not np.all(res.valid):
        return math.nan, math.nan
    tau = np.asarray(res.tau)
    return float(np.max(np.abs(tau))), float(np.sqrt(np.mean(tau**2)))


def _evaluate(study: DesignStudy, params: list[Any], rows: np.ndarray, seed: Any) -> dict[str, np.ndarray]:
    assert isinstance(study, ModelStudy)
    n = len(params)
    out = {m.name: np.full(n, np.nan) for m in study.metrics}
    ok = np.zeros(n, bool)
    for i, p in enumerate(params):
        if p is None:
            continue
        try:
            vals = _one_design(study, p)
        except Exception:  # build or the engine refused this design: a failed design, never the batch
            continue
        ok[i] = True
        for m in study.metrics:
            out[m.name][i] = vals.get(m.name, math.nan)
    out["design_ok"] = ok
    return out


def load_model(spec: str) -> Callable[..., Any]:
    """The function ``NAME`` of the Python file ``FILE.py`` from ``"FILE.py:NAME"``, or a template
    builder of an ``.xml`` / ``.urdf`` file (:func:`template_builder`).

    The file is loaded as a module whose functions are pickled by value (cloudpickle), so Dask workers
    run them without the file on their path.

    Parameters
    ----------
    spec : str
        ``"path/to/model.py:build"`` or ``"path/to/model.xml"``.

    Returns
    -------
    callable
        ``build(**params) -> Mechanism``.

    Raises
    ------
    ValueError
        If the file does not exist, cannot be imported, or has no callable ``NAME``.
    """
    if not isinstance(spec, str) or not spec:
        raise ValueError(f"Expected spec to be 'FILE.py:NAME' or a template file, got {spec!r}.")
    path_s, sep, attr = spec.rpartition(":")
    if not sep or not attr.isidentifier():
        path_s, attr = spec, "build"
    path = Path(path_s)
    if path.suffix in (".xml", ".urdf", ".mjcf"):
        return template_builder(path)
    if not path.is_file():
        raise ValueError(f"Expected spec (--model FILE.py:NAME) to name an existing file, got {spec!r}.")
    import hashlib

    # the same module name in every process (str hash() is salted per process)
    name = "robomech_user_model_" + hashlib.sha256(str(path.resolve()).encode()).hexdigest()[:16]
    try:
        mod_spec = importlib.util.spec_from_file_location(name, path)
        assert mod_spec is not None and mod_spec.loader is not None
        module = importlib.util.module_from_spec(mod_spec)
        sys.modules[name] = module
        mod_spec.loader.exec_module(module)
    except Exception as exc:
        raise ValueError(
            f"Expected spec (--model) {spec!r} to import, got {type(exc).__name__}: {exc}"
        ) from exc
    fn = getattr(module, attr, None)
    if not callable(fn):
        raise ValueError(
            f"Expected spec (--model) {spec!r} to name a function of the file, got {type(fn).__name__}."
        )
    import cloudpickle

    cloudpickle.register_pickle_by_value(module)
    return fn


@dataclass(frozen=True)
class _Template:
    text: str
    kind: str  # "format" ({L1}) or "template" ($L1)
    names: tuple[str, ...]

    def __call__(self, **params: float) -> Any:
        from robomech import multibody as mb

        missing = set(self.names) - set(params)
        if missing:
            raise ValueError(f"Expected values for the template's parameters {sorted(missing)}.")
        values = {k: repr(float(v)) for k, v in params.items()}
        text = (
            string.Template(self.text).substitute(values)
            if self.kind == "template"
            else self.text.format(**values)
        )
        return mb.from_mjcf(text)


def template_builder(path: Path | str) -> Callable[..., Any]:
    """``build(**params)`` from an MJCF/URDF file whose numbers are named parameters.

    Placeholders are ``$NAME`` / ``${NAME}`` (Python's ``string.Template``) when the file holds a ``$``,
    else ``{NAME}`` (``str.format``; write literal braces as ``{{ }}``).  Each design substitutes
    its variables' values and loads the text with :func:`robomech.multibody.from_mjcf` (MuJoCo's
    parser: MJCF or URDF).

    Parameters
    ----------
    path : str or pathlib.Path
        The template file.

    Returns
    -------
    callable
        ``build(**params) -> Mechanism`` (picklable), whose ``names`` are the placeholders.

    Raises
    ------
    ValueError
        If the file does not exist or holds no placeholder.
    """
    if not isinstance(path, str | Path) or not Path(path).is_file():
        raise ValueError(f"Expected path to be an existing template file, got {path!r}.")
    text = Path(path).read_text(encoding="utf-8")
    if "$" in text:
        names = tuple(
            sorted(
                {
                    m.group("named") or m.group("braced")
                    for m in string.Template.pattern.finditer(text)
                    if m.group("named") or m.group("braced")
                }
            )
        )
        kind = "template"
    else:
        names = tuple(sorted({f for _, f, _, _ in string.Formatter().parse(text) if f}))
        kind = "format"
    if not names:
        raise ValueError(
            f"Expected path {str(path)!r} to be a template holding named parameters "
            "({L1} or $L1), got none."
        )
    return _Template(text, kind, names)
