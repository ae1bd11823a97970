"""Design exploration at scale: dimensional synthesis and tolerance studies on Dask, results in Zarr.

A :class:`DesignStudy` maps design variables onto a mechanism's frozen parameter dataclass
(``dataclasses.replace``) or onto manufacturing errors, and computes metrics per design with the
mechanism's batched kernels.  :func:`run_sweep` evaluates chunks of designs as Dask tasks (a LocalCluster
by default, or an existing cluster) and writes a resumable Zarr store; :func:`optimize_nsga2` runs pymoo's
NSGA-II with its populations evaluated by the same machinery.  ``robomech sweep`` is the command line.
:func:`model_study` makes a study of any parametrized description (``build(**params) -> Mechanism`` or
an MJCF/URDF template) with generic, engine-computed metrics.  :func:`open_results` returns an
``xarray.Dataset``.  See ``docs/explore.md``.  dask, distributed, zarr, pymoo and xarray are imported
on first use only.
"""

from __future__ import annotations

from ._model import GENERIC_METRICS, ModelStudy, UserMetric, load_model, model_study, template_builder
from ._optimize import optimize_nsga2
from ._pareto import pareto_front
from ._runner import SchedulerUnreachable, SweepSummary, local_cluster, run_sweep
from ._sampling import SAMPLERS, chunk_seed, design_matrix
from ._store import StoreDamaged, StoreMismatch, open_results
from ._study import DesignStudy, Metric, Objective, Variable, with_variables

__all__ = [
    "GENERIC_METRICS",
    "SAMPLERS",
    "DesignStudy",
    "Metric",
    "ModelStudy",
    "Objective",
    "SchedulerUnreachable",
    "StoreDamaged",
    "StoreMismatch",
    "SweepSummary",
    "UserMetric",
    "Variable",
    "available_studies",
    "chunk_seed",
    "design_matrix",
    "get_study",
    "load_model",
    "local_cluster",
    "model_study",
    "open_results",
    "optimize_nsga2",
    "pareto_front",
    "run_sweep",
    "template_builder",
    "with_variables",
]

_BUILTIN = ("_spherical_leg", "_vectored_thrust", "_omnileg")


def available_studies() -> dict[str, DesignStudy]:
    """The built-in design studies by name.

    Returns
    -------
    dict of str to DesignStudy
        Every registered study, keyed by its ``name``.

    Examples
    --------
    >>> from robomech.explore import available_studies
    >>> sorted(available_studies())
    ['omnileg-synthesis', 'spherical-leg-synthesis', 'vectored-thrust-tolerance']
    """
    import importlib

    out = {}
    for mod in _BUILTIN:
        s = importlib.import_module(f"{__name__}.{mod}").STUDY
        out[s.name] = s
    return out


def get_study(name: str) -> DesignStudy:
    """The built-in design study called ``name`` (ValueError listing the valid names otherwise).

    Parameters
    ----------
    name : str
        A key of :func:`available_studies`.

    Returns
    -------
    DesignStudy

    Raises
    ------
    ValueError
        If ``name`` is not a str or not a registered study (the message lists the valid names).

    Examples
    --------
    >>> from robomech.explore import get_study
    >>> get_study("omnileg-synthesis").variable_names
    ('L1', 'L4', 'L5')
    """
    if not isinstance(name, str):
        raise ValueError(f"Expected name to be a study name (str), got {type(name).__name__}.")
    studies = available_studies()
    if name not in studies:
        raise ValueError(
            f"Expected name to be a design study, got unknown {name!r}; "
            f"valid studies are: {', '.join(studies)}."
        )
    return studies[name]
