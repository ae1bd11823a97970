"""A design study of any described mechanism: a parametrized description, variables, a task, metrics.

The description is ``build(**params) -> Mechanism`` (the multibody :class:`~robomech.multibody.Builder`,
or :func:`~robomech.multibody.from_mjcf` of text the function formats), or an MJCF/URDF template file
whose numbers are named parameters (``{L1}`` or ``$L1``, :func:`template_builder`).  Each design is one
call of ``build``; the generic metrics are computed by the engine's public API
(:func:`~robomech.multibody.inverse_kinematics`, :func:`~robomech.multibody.site_jacobian`,
:func:`~robomech.multibody.singularities`, :func:`~robomech.multibody.forward_kinematics`,
:func:`~robomech.multibody.inverse_dynamics`) on the study's task, evaluated for every design of a
chunk in one kernel call per step by the design-batched drivers of ``multibody._designs`` (the same
per-sample kernels as the public functions).
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
    chunk: int = 32,
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
        Designs per Dask task (>= 1; default 32: the designs of a chunk share each batched kernel call).

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


def _task_of(study: ModelStudy, batch: Any) -> tuple[np.ndarray, float]:
    """The task points ``(D, m, 3)`` of a batch of designs and one cell's measure (a box's grid is placed
    at each design's reference off-axis position of the site)."""
    from robomech.multibody._designs import site_poses_designs

    if study.box is None:
        task = np.asarray(study.task, dtype=float)
        return np.broadcast_to(task, (batch.n, *task.shape)), math.nan
    z0 = site_poses_designs(batch, np.arange(batch.n), batch.q_ref)[:, :3, 3]
    grids = [task_grid(np.asarray(study.box), study.grid, study.outputs, z) for z in z0]
    return np.stack([g[0] for g in grids]), grids[0][1]


def _weights(outputs: str) -> np.ndarray:
    w = np.zeros(6)
    for a in outputs:
        w[3 + AXES.index(a)] = 1.0
    return w


def _targets(points: np.ndarray) -> np.ndarray:
    T = np.broadcast_to(np.eye(4), (points.shape[0], 4, 4)).copy()
    T[:, :3, 3] = points
    return T


TASK_METRICS = frozenset(
    {
        "workspace_measure",
        "task_fraction",
        "dexterity_min",
        "dexterity_mean",
        "type2_distance",
        "constraint_distance",
    }
)


def _task_metrics(study: ModelStudy, batch: Any) -> dict[str, np.ndarray]:
    """The task metrics ``(D,)`` of a batch of designs of one structure: one batched IK over every
    design's task points (plus the neighbour retries), one batched evaluation of the site Jacobian and
    the constraint matrix at every reached point."""
    from robomech.multibody._designs import site_measures_designs

    gen = set(study.generic)
    pts, cell = _task_of(study, batch)
    D, P = pts.shape[:2]
    if study.box is None:
        q, ok = reach_designs(batch, pts, study.outputs)
    else:
        q, ok = reach_grid(batch, pts, study.grid, study.outputs)
    reached = ok.sum(axis=1)
    out: dict[str, np.ndarray] = {
        "workspace_measure": reached * cell,
        "task_fraction": reached / P,
    }
    if gen & {"dexterity_min", "dexterity_mean", "type2_distance", "constraint_distance"}:
        di = np.repeat(np.arange(D), P)[ok.ravel()]
        rows = [3 + AXES.index(a) for a in study.outputs]
        want = (
            bool(gen & {"dexterity_min", "dexterity_mean"}),
            "type2_distance" in gen,
            "constraint_distance" in gen,
        )
        inv, s2, sc = site_measures_designs(
            batch, di, q.reshape(D * P, -1)[ok.ravel()], rows, study.length, want
        )
        bounds = np.concatenate([[0], np.cumsum(reached)])
        for name, x, red in (
            ("dexterity_min", inv, np.min),
            ("dexterity_mean", inv, np.mean),
            ("type2_distance", s2, np.min),
            ("constraint_distance", sc, np.min),
        ):
            out[name] = np.array(
                [float(red(x[bounds[d] : bounds[d + 1]])) if reached[d] else math.nan for d in range(D)]
            )
    return out


# Rounds of re-solving the task points the IK missed from their nearest reached neighbour's configuration.
IK_RETRIES = 2
# On a task grid, re-solve only the missed points within this many cells of a reached one (1.5: the
# eight neighbours of a cell).
RETRY_CELLS = 1.5
# Continuation stages of such a re-solve (the neighbour's pose is one task cell or more away).
IK_RETRY_STEPS = 4
# The task IK also stops a point at a stationary point of its cost that leaves a residual: every
# column of the constraint-and-site matrix at an angle to the residual whose cosine is at most this
# (MINPACK's gtol test; a point out of reach, which would otherwise spend the iteration limit).  On
# 8 random five-bar designs x 32 x 32 points it lost none of 3,498 reached points and cut the mean
# iterations 39.5 -> 28.5 (3e-3 lost one); a reachable point it stops early is re-solved from a
# reached neighbour (IK_RETRIES; reach_grid's wavefront).
IK_GTOL = 1e-3


# Seeds of a task grid: every GRID_SEED_STRIDE-th cell per axis (the middle one of each block) is solved
# from the reference configuration; the rest of the grid is reached from them (reach_grid).
GRID_SEED_STRIDE = 4
# Continuation stages of reach_grid's last round (each seed missed from the reference, next to the
# reached region, re-solved from its first reached neighbour).  Measured on 64 Sobol five-bar designs x
# 32 x 32 cells: with 2 (and with 4) every cell the annuli closed form puts inside (27,452, boundary cells
# within 1e-6 m excluded) is reached and none outside; without this round 5 were missed.  The round
# re-solves seeds only: on 256 designs every cell it recovered (27) was a seed, and re-solving the other
# missed cells next to the reached region too recovered none of 24,950 on 1,024 designs, at 14 % of the
# IK iterations.  A seed it recovers is no source for other cells (solved from a neighbour in the
# wavefront instead, it would hand its assembly branch on: other dexterities in 2 of 1,024 designs).
GRID_LAST_STEPS = 2


def _grid_neighbours(n: int, k: int) -> np.ndarray:
    """``(n_offsets, n**k)``: the flat index of each cell's neighbour within ``RETRY_CELLS`` cells, per
    offset in a fixed order (-1 outside the grid)."""
    import itertools

    idx = np.indices((n,) * k).reshape(k, -1).T
    out = []
    for o in itertools.product((-1, 0, 1), repeat=k):
        if not 0 < np.linalg.norm(o) <= RETRY_CELLS:
            continue
        j = idx + np.array(o)
        inside = np.all((j >= 0) & (j < n), axis=1)
        out.append(np.where(inside, np.ravel_multi_index(tuple(np.clip(j, 0, n - 1).T), (n,) * k), -1))
    return np.array(out)


# Slack of the reach bound's test (relative to the bound plus L): the rounding of the kinematics and of
# the bound's own sums, far below any task cell.
REACH_BOUND_RTOL = 1e-9


def _chain_bound(batch: Any, body: int, point: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """A sphere ``(centre (D, 3), radius (D,))`` that holds ``point (D, 3)`` (fixed in ``body``) at every
    configuration: from ``body`` up to the world, each body has at most one joint, a hinge or a ball,
    which rotates everything below it about its anchor (fixed in the parent's frame), so the point's
    distance from the topmost anchor is at most the sum of the (rigid) distances from the point to its
    body's anchor and from each anchor to the next one up (triangle inequality).  A slide, a free
    joint or a body with several joints on the path: radius inf."""
    t, g = batch.tables, batch.geometry
    D = batch.n
    P = point.copy()  # the current point, in the current body's frame
    radius = np.zeros(D)
    b = body
    while b > 0:
        js = range(int(t.j0[b]), int(t.j0[b + 1]))
        if len(js) > 1 or (len(js) == 1 and t.jtype[js[0]] not in (0, 2)):  # hinge 0, ball 2
            return np.zeros((D, 3)), np.full(D, np.inf)
        if len(js) == 1:
            a = g.jpos[:, js[0]]
            radius += np.linalg.norm(P - a, axis=1)
            P = a
        P = np.einsum("dij,dj->di", g.T_off[:, b, :3, :3], P) + g.T_off[:, b, :3, 3]
        b = int(t.parent[b])
    return P, radius


def reach_bound(batch: Any) -> tuple[np.ndarray, np.ndarray]:
    """Spheres ``(centres (D, S, 3), radii (D, S))`` per design (m), each holding the batch's site at
    every configuration the IK can call converged (radius inf: no bound): the site's own chain
    (:func:`_chain_bound`), and for each closure point pair with one point on the site's body, the other
    point's chain plus the (rigid) distance from the site to this point and the closure tolerance
    (a converged configuration closes each pair to ``CONVERGED_RTOL * L`` per row)."""
    from robomech.multibody._options import CONVERGED_RTOL

    t, g = batch.tables, batch.geometry
    sb = batch.site_body
    site = batch.T_site[:, :3, 3]
    centres, radii = [], []
    c, r = _chain_bound(batch, sb, site)
    centres.append(c)
    radii.append(r)
    for i in range(t.pp.shape[0]):
        for this, other in ((0, 1), (1, 0)):
            if int(t.pp[i, this]) != sb:
                continue
            c, r = _chain_bound(batch, int(t.pp[i, other]), g.px[:, i, other])
            r = (
                r
                + np.linalg.norm(site - g.px[:, i, this], axis=1)
                + np.sqrt(3) * CONVERGED_RTOL * batch.length
            )
            centres.append(c)
            radii.append(r)
    return np.stack(centres, 1), np.stack(radii, 1)


def _out_of_reach(batch: Any, pts: np.ndarray, outputs: str) -> np.ndarray:
    """Which targets ``pts (D, P, 3)`` (design ``d`` of the batch in row ``d``) are farther along
    ``outputs`` from one of the design's :func:`reach_bound` spheres than the IK's convergence
    tolerance: no configuration converges there ``(D, P)``."""
    from robomech.multibody._options import CONVERGED_RTOL

    centres, radii = reach_bound(batch)
    ax = [AXES.index(a) for a in outputs]
    L = batch.length[:, None]
    reach = radii + np.sqrt(len(ax)) * CONVERGED_RTOL * L + REACH_BOUND_RTOL * (radii + L)  # (D, S)
    far = np.zeros(pts.shape[:2], bool)
    for s in range(radii.shape[1]):
        d2 = np.zeros(pts.shape[:2])
        for a in ax:
            d2 += (pts[:, :, a] - centres[:, s, a][:, None]) ** 2
        far |= np.sqrt(d2) > reach[:, s][:, None]
    return far


def reach_grid(batch: Any, pts: np.ndarray, n: int, outputs: str) -> tuple[np.ndarray, np.ndarray]:
    """Configurations ``q (D, n**k, nq)`` placing the batch's site at each design's task-grid points
    ``pts (D, n**k, 3)`` (``task_grid`` order, ``n`` cells per axis) along ``outputs``, and which
    converged ``(D, n**k)``: a wavefront over the grid.

    The seed cells (every ``GRID_SEED_STRIDE``-th cell per axis) are solved from each design's
    reference configuration (one batched IK); then, round after round, every cell not yet tried that
    has a reached neighbour (within ``RETRY_CELLS`` cells) is solved from that neighbour's configuration
    (the first such neighbour in a fixed order), all designs' cells of a round in one batched IK, until
    no untried cell has a reached neighbour; a last round re-solves each seed missed from the
    reference that borders the reached region from its first reached neighbour in ``GRID_LAST_STEPS``
    continuation stages.  A cell is reached if it is connected through reached cells to a seed reached
    from the reference (the IK is a local solver: a region of the grid not so connected is missed).  A
    cell out of reach costs an IK solve only if it borders the reached region (a solve from the
    reference of every cell, as :func:`reach_designs`, spends most of its iterations on the cells out
    of reach), and none if it lies outside one of the design's :func:`reach_bound` spheres (no
    configuration the IK calls converged does).
    """
    from robomech.multibody._designs import ik_designs

    D, P = pts.shape[:2]
    k = len(outputs)
    w = _weights(outputs)
    T = _targets(pts.reshape(-1, 3)).reshape(D, P, 4, 4)
    q = np.full((D, P, batch.q_ref.shape[1]), np.nan)
    ok = np.zeros((D, P), bool)
    cells = np.indices((n,) * k).reshape(k, -1).T
    seed = np.flatnonzero(np.all(cells % GRID_SEED_STRIDE == GRID_SEED_STRIDE // 2, axis=1))
    if seed.size == 0:  # a grid smaller than one stride: its middle cell
        seed = np.array([int(np.ravel_multi_index((n // 2,) * k, (n,) * k))])
    far = _out_of_reach(batch, pts, outputs)  # targets no configuration reaches: missed without a solve
    d, p = np.repeat(np.arange(D), seed.size), np.tile(seed, D)
    d, p = d[~far[d, p]], p[~far[d, p]]
    qj, cj, _, _, _ = ik_designs(batch, d, T[d, p], batch.q_ref[d], w, gtol=IK_GTOL)
    ok[d, p] = cj
    q[d[cj], p[cj]] = qj[cj]
    tried = np.zeros((D, P), bool)
    tried[:, seed] = True
    nb = _grid_neighbours(n, k)
    while True:
        src = np.full((D, P), -1)
        for j in nb:  # the first reached neighbour of each untried cell, in the offsets' order
            has = (j >= 0)[None, :] & ok[:, np.maximum(j, 0)] & ~tried & (src < 0)
            src[has] = np.broadcast_to(j, (D, P))[has]
        d, p = np.nonzero(src >= 0)
        if d.size == 0:
            break
        tried[d, p] = True
        d, p = d[~far[d, p]], p[~far[d, p]]
        if d.size == 0:
            continue
        qj, cj, _, _, _ = ik_designs(batch, d, T[d, p], q[d, src[d, p]], w, gtol=IK_GTOL)
        ok[d, p] = cj
        q[d[cj], p[cj]] = qj[cj]
    # the last round: each seed missed from the reference, next to the reached region, once more from
    # its first reached neighbour in GRID_LAST_STEPS continuation stages (not a source for others)
    missed = np.zeros((D, P), bool)
    missed[:, seed] = ~ok[:, seed] & ~far[:, seed]
    src = np.full((D, P), -1)
    for j in nb:
        has = (j >= 0)[None, :] & ok[:, np.maximum(j, 0)] & missed & (src < 0)
        src[has] = np.broadcast_to(j, (D, P))[has]
    d, p = np.nonzero(src >= 0)
    if d.size:
        qj, cj, _, _, _ = ik_designs(
            batch, d, T[d, p], q[d, src[d, p]], w, steps=GRID_LAST_STEPS, gtol=IK_GTOL
        )
        ok[d, p] = cj
        q[d[cj], p[cj]] = qj[cj]
    return q, ok


def _nearest(pts: np.ndarray, ok: np.ndarray, radius: float | None) -> tuple[np.ndarray, np.ndarray]:
    """The missed points of one design and, for each, its nearest reached point (k-d tree), keeping
    only those within ``radius`` (m) of it when given."""
    from scipy.spatial import cKDTree

    miss, have = np.flatnonzero(~ok), np.flatnonzero(ok)
    dist, near = cKDTree(pts[have]).query(pts[miss], k=1)
    if radius is not None:
        keep = dist <= radius
        miss, near = miss[keep], near[keep]
    return miss, have[near]


def reach_designs(
    batch: Any, pts: np.ndarray, outputs: str, radius: float | None = None
) -> tuple[np.ndarray, np.ndarray]:
    """Configurations ``q (D, m, nq)`` placing the batch's site at each design's task points
    ``pts (D, m, 3)`` along ``outputs``, and which converged ``(D, m)``.

    One batched inverse kinematics (``multibody._designs.ik_designs``, the Levenberg–Marquardt
    iteration of :func:`~robomech.multibody.inverse_kinematics`, stopped also at a stationary point
    that leaves a residual: ``IK_GTOL``) from each design's reference
    configuration, then up to ``IK_RETRIES`` rounds re-solving each missed point from the configuration
    of the nearest reached point of its design (continuation in ``IK_RETRY_STEPS`` stages): the IK is
    a local solver, and a reachable point far from the reference configuration can be missed from
    ``q0`` alone.  With ``radius`` (m) only the missed points within ``radius`` of a reached one are
    re-solved (on a task grid, the cells next to the reached region: each round grows it by one cell).
    A design stops retrying when a round has nothing to re-solve or reaches nothing new.
    """
    from robomech.multibody._designs import ik_designs

    D, P = pts.shape[:2]
    w = _weights(outputs)
    di = np.repeat(np.arange(D), P)
    T = _targets(pts.reshape(-1, 3))
    qf, conv, _, _, _ = ik_designs(batch, di, T, batch.q_ref[di], w, gtol=IK_GTOL)
    q = qf.reshape(D, P, -1)
    ok = conv.reshape(D, P).copy()
    active = np.ones(D, bool)
    for _ in range(IK_RETRIES):
        jobs = []
        for d in np.flatnonzero(active):
            if ok[d].all() or not ok[d].any():
                active[d] = False
                continue
            miss, near = _nearest(pts[d], ok[d], radius)
            if miss.size == 0:
                active[d] = False
                continue
            jobs.append((d, miss, near))
        if not jobs:
            break
        dj = np.concatenate([np.full(m.size, d) for d, m, _ in jobs])
        Tj = _targets(np.concatenate([pts[d, m] for d, m, _ in jobs]))
        guess = np.concatenate([q[d, n] for d, _, n in jobs])
        qj, cj, _, _, _ = ik_designs(batch, dj, Tj, guess, w, steps=IK_RETRY_STEPS, gtol=IK_GTOL)
        start = 0
        for d, miss, _ in jobs:
            got = cj[start : start + miss.size]
            if not got.any():
                active[d] = False
            q[d, miss[got]] = qj[start : start + miss.size][got]
            ok[d, miss[got]] = True
            start += miss.size
    return q, ok


def reach(
    mech: Any, site: str, pts: np.ndarray, outputs: str, radius: float | None = None, grid: int | None = None
) -> tuple[np.ndarray, np.ndarray]:
    """:func:`reach_designs` of one design (:func:`reach_grid` for the points of a task grid of ``grid``
    cells per axis, as a study's ``task_box``): ``q (m, nq)`` placing ``site`` at ``pts (m, 3)`` along
    ``outputs``, and which converged ``(m,)``."""
    from robomech.multibody._designs import design_batch

    batch, P = design_batch([mech], site), np.asarray(pts, float)[None]
    q, ok = reach_designs(batch, P, outputs, radius) if grid is None else reach_grid(batch, P, grid, outputs)
    return q[0], ok[0]


def dexterity(mech: Any, q: np.ndarray, site: str, outputs: str, length: float | None = None) -> np.ndarray:
    """Inverse condition numbers ``sigma_min / sigma_max (m,)`` of the scaled output Jacobian at ``q``.

    The rows are the site's linear velocity along ``outputs`` (m/s); each hinge actuator's column is
    divided by the characteristic length L (``length``, default ``mech.length``) so that every entry is
    dimensionless (a slide's column is m/m already).  1 is isotropic, 0 singular.  The study's kernel
    (``multibody._designs.site_measures_designs``) on one design.
    """
    from robomech.multibody._designs import design_batch, site_measures_designs

    if q.shape[0] == 0:
        return np.zeros(0)
    rows = [3 + AXES.index(a) for a in outputs]
    one, di = design_batch([mech], site), np.zeros(q.shape[0], np.int64)
    return site_measures_designs(one, di, q, rows, length, (True, False, False))[0]


def task_forces_designs(
    mechs: Sequence[Any], batch: Any, site: str, outputs: str, trajectory: tuple[np.ndarray, np.ndarray]
) -> tuple[np.ndarray, np.ndarray]:
    """Peak and RMS actuator force ``(D,)`` of each design along ``trajectory = (t, points)``: IK of
    every design at each time with its previous solution as the guess (one batched call per time),
    actuator rates by second-order finite differences in time (``numpy.gradient``), then inverse
    dynamics with gravity of every design x time in one design-batched kernel call
    (``multibody._designs.inverse_dynamics_designs``: :func:`~robomech.multibody.inverse_dynamics` per
    sample); NaN for a design where any sample fails (not reached, singular, not valid)."""
    from robomech.multibody._designs import ik_designs, inverse_dynamics_designs

    t, pts = trajectory
    D = batch.n
    w = _weights(outputs)
    alive = np.ones(D, bool)
    guess = batch.q_ref.copy()
    qs = np.full((t.size, D, guess.shape[1]), np.nan)
    for i in range(t.size):
        di = np.flatnonzero(alive)
        if di.size == 0:
            break
        qi, conv, _, _, _ = ik_designs(
            batch, di, _targets(np.repeat(pts[i : i + 1], di.size, 0)), guess[di], w, steps=4 if i == 0 else 1
        )
        alive[di[~conv]] = False
        qs[i, di] = qi
        guess[di] = qi
    peak, rms = np.full(D, math.nan), np.full(D, math.nan)
    live = np.flatnonzero(alive)
    if live.size == 0:
        return peak, rms
    q = qs[:, live].transpose(1, 0, 2)  # (designs, times, nq)
    qa = q[:, :, [mechs[0].qpos_address(j) for j in mechs[0].actuated]]
    qd = np.gradient(qa, t, axis=1, edge_order=2)
    qdd = np.gradient(qd, t, axis=1, edge_order=2)
    na = qa.shape[2]
    res = inverse_dynamics_designs(
        batch, np.repeat(live, t.size), q.reshape(-1, q.shape[2]), qd.reshape(-1, na), qdd.reshape(-1, na)
    )
    valid = res["valid"].reshape(live.size, t.size)
    taus = res["tau"].reshape(live.size, t.size, na)
    for j, d in enumerate(live.tolist()):
        if np.all(valid[j]):
            tau = taus[j]
            peak[d], rms[d] = float(np.max(np.abs(tau))), float(np.sqrt(np.mean(tau**2)))
    return peak, rms


def task_forces(
    mech: Any, site: str, outputs: str, trajectory: tuple[np.ndarray, np.ndarray]
) -> tuple[float, float]:
    """:func:`task_forces_designs` of one design: peak and RMS actuator force along ``trajectory``."""
    from robomech.multibody._designs import design_batch

    peak, rms = task_forces_designs([mech], design_batch([mech], site), site, outputs, trajectory)
    return float(peak[0]), float(rms[0])


def _build(study: ModelStudy, params: dict[str, float]) -> Any:
    """The design's mechanism (raises if it cannot be built or lacks the site: a failed design)."""
    from robomech import multibody as mb

    mech = study.build(**params)
    if not isinstance(mech, mb.Mechanism):
        raise TypeError(f"build returned {type(mech).__name__}, not a Mechanism")
    mech.site(study.site)  # a design without the site fails here
    return mech


def _batch_metrics(study: ModelStudy, mechs: Sequence[Any]) -> dict[str, np.ndarray]:
    """The engine metrics ``(D,)`` of designs of one structure (raises: the caller falls back to one
    design at a time)."""
    from robomech.multibody._designs import design_batch

    gen = set(study.generic)
    batch = design_batch(mechs, study.site)
    out: dict[str, np.ndarray] = {}
    if gen & TASK_METRICS:
        out.update(_task_metrics(study, batch))
    if gen & {"peak_force", "rms_force"} and study.trajectory is not None:
        out["peak_force"], out["rms_force"] = task_forces_designs(
            mechs, batch, study.site, study.outputs, study.trajectory
        )
    if "assembly_failure" in gen:
        out["assembly_failure"] = assembly_failure_designs(mechs, batch, study.input_box, study.input_grid)
    return out


def assembly_failure_designs(mechs: Sequence[Any], batch: Any, input_box: Any, grid: int) -> np.ndarray:
    """Fraction ``(D,)`` of the ``grid``-per-axis actuator grid over ``input_box`` where each design
    does not assemble: :func:`~robomech.multibody.forward_kinematics` from the design's reference (its
    closure solve for every design x grid point in one kernel call, ``multibody._designs.closure_designs``;
    then its convergence rule per design: closure within ``CONVERGED_RTOL * L``, the same assembly mode
    as the reference)."""
    from robomech._validation import MAX_MAGNITUDE
    from robomech.multibody._assembly import assembly_mode_sign, floating_base_dofs
    from robomech.multibody._designs import closure_designs
    from robomech.multibody._options import CONVERGED_RTOL

    m0 = mechs[0]
    box = np.asarray(input_box)
    if box.shape[0] != len(m0.actuated):
        raise ValueError(f"input_box has {box.shape[0]} rows, the mechanism {len(m0.actuated)} actuators")
    axes = [np.linspace(lo, hi, grid) for lo, hi in box]
    qa = np.stack(np.meshgrid(*axes, indexing="ij"), -1).reshape(-1, box.shape[0])
    G = qa.shape[0]
    tree = m0.tree
    ok = np.all(np.isfinite(qa) & (np.abs(qa) <= MAX_MAGNITUDE), axis=-1)  # as the public function
    start = np.stack([np.asarray(m.q0, dtype=float) for m in mechs])  # (D, nq) the assembled references
    di = np.repeat(np.arange(len(mechs)), G)
    q = start[di]
    a0 = q[:, tree.act_qadr]
    target = np.where(np.tile(ok, len(mechs))[:, None], np.tile(qa, (len(mechs), 1)), a0)
    q[:, tree.act_qadr] = a0 + (target - a0) * 1.0  # the public function's one continuation stage
    free = np.setdiff1d(np.arange(tree.nv), np.concatenate([tree.act_dof, floating_base_dofs(m0)]))
    q, rc, _ = closure_designs(batch, di, q, free)
    out = np.empty(len(mechs))
    for d, mech in enumerate(mechs):
        s = slice(d * G, (d + 1) * G)
        flipped = (assembly_mode_sign(mech, np.broadcast_to(start[d], (G, start.shape[1])), q[s]) < 0) & ok
        conv = ok & (rc[s] <= CONVERGED_RTOL * mech.tree.length) & ~flipped
        out[d] = float(1.0 - np.mean(conv))
    return out


def _design_metrics(study: ModelStudy, mech: Any, params: dict[str, float]) -> dict[str, float]:
    """The metrics evaluated one design at a time: the user metrics."""
    out: dict[str, float] = {}
    for u in study.user_metrics:
        try:
            out[u.name] = float(u.fn(mech, dict(params)))
        except Exception:  # a user metric failing on one design: NaN for that design only
            out[u.name] = math.nan
    return out


def _evaluate(study: DesignStudy, params: list[Any], rows: np.ndarray, seed: Any) -> dict[str, np.ndarray]:
    """Every metric of a chunk of designs: each design built (``build`` per design), the designs
    grouped by compiled structure, each group's engine metrics in one batched kernel call per step
    (:func:`_batch_metrics`), a group that raises re-run one design at a time (a design that raises
    alone is a failed design, never the chunk)."""
    from robomech.multibody._designs import group_designs

    assert isinstance(study, ModelStudy)
    n = len(params)
    out = {m.name: np.full(n, np.nan) for m in study.metrics}
    ok = np.zeros(n, bool)
    mechs: list[Any] = [None] * n
    vals: list[dict[str, float]] = [{} for _ in range(n)]
    for i, p in enumerate(params):
        if p is None:
            continue
        try:
            mechs[i] = _build(study, p)
            vals[i].update(_design_metrics(study, mechs[i], p))
        except Exception:  # build or the engine refused this design: a failed design, never the batch
            mechs[i] = None
    live = [i for i in range(n) if mechs[i] is not None]
    try:
        groups = [g[0] for g in group_designs([mechs[i] for i in live], study.site)] if live else []
    except Exception:  # one batch per design: the designs that raise alone fail below
        groups = [np.array([k]) for k in range(len(live))]
    for idx in groups:
        members = [live[k] for k in idx]
        try:
            res = _batch_metrics(study, [mechs[i] for i in members])
            per = [{k: float(v[j]) for k, v in res.items()} for j in range(len(members))]
        except Exception:  # one design at a time: only the designs that raise alone fail
            per = []
            for i in members:
                try:
                    res = _batch_metrics(study, [mechs[i]])
                    per.append({k: float(v[0]) for k, v in res.items()})
                except Exception:
                    per.append(None)  # type: ignore[arg-type]
        for i, v in zip(members, per, strict=True):
            if v is None:
                mechs[i] = None
            else:
                vals[i].update(v)
    for i in range(n):
        if mechs[i] is None:
            continue
        ok[i] = True
        for m in study.metrics:
            out[m.name][i] = vals[i].get(m.name, math.nan)
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
