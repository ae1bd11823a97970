"""What a design study is: variables, metrics, and a per-design evaluation from the batched kernels.

A :class:`DesignStudy` maps each row of a design matrix onto the mechanism's frozen parameter dataclass
(``dataclasses.replace`` of the study's nominal parameters, for ``kind="range"`` variables) or onto an
as-built error vector (``kind="normal"`` variables: a manufacturing error with standard deviation
``sigma``), and evaluates its metrics on the study's pose set with the mechanism's batched kernels.
A design whose parameters the dataclass rejects is a failed sample (``design_ok`` False, metrics NaN),
never an exception: a sweep never dies of one bad design.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Callable, Collection, Iterator, Mapping, Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from robomech._validation import check_choice, check_int, check_positive, check_real, coerce_int_fields

__all__ = ["DesignStudy", "Metric", "Objective", "Variable", "with_variables"]

KINDS = ("range", "normal")


@dataclass(frozen=True)
class Variable:
    """One design variable.

    ``kind="range"``: a field ``name`` of the study's parameter dataclass, sampled in ``[low, high]``
    (SI units).  ``kind="normal"``: a manufacturing error ``name`` of the study, zero mean and standard
    deviation ``sigma`` (SI units).

    Parameters
    ----------
    name : str
        A Python identifier: the parameter field (range) or manufacturing error (normal) it sets.
    low, high : float, optional
        The range ``low < high``, both finite (SI units: m, rad, ...); required for ``kind="range"``.
    unit : str, optional
        Unit label for reports (e.g. ``"m"``).
    kind : str, optional
        ``"range"`` (default, uniform over ``[low, high]``) or ``"normal"``.
    sigma : float, optional
        Standard deviation (> 0, SI units); required for ``kind="normal"``.
    description : str, optional
        Free text for reports.

    Raises
    ------
    ValueError
        If ``name`` is not an identifier, ``kind`` is unknown, the range is not finite with
        ``low < high`` (range), or ``sigma`` is not positive (normal).

    Examples
    --------
    >>> import numpy as np
    >>> v = Variable("L1", 0.1, 0.2, unit="m")
    >>> v.from_unit(np.array([0.0, 0.5, 1.0]))
    array([0.1 , 0.15, 0.2 ])
    """

    name: str
    low: float = math.nan
    high: float = math.nan
    unit: str = ""
    kind: str = "range"
    sigma: float = math.nan
    description: str = ""

    def __post_init__(self) -> None:
        if not isinstance(self.name, str) or not self.name.isidentifier():
            raise ValueError(f"Expected name to be an identifier (a variable name), got {self.name!r}.")
        check_choice(self.kind, "kind", KINDS)
        _check_text(self.unit, "unit")
        _check_text(self.description, "description")
        if self.kind == "range":
            lo = check_real(self.low, "low", finite=False)
            hi = check_real(self.high, "high", finite=False)
            if not (math.isfinite(lo) and math.isfinite(hi)):
                raise ValueError(
                    f"Expected low and high of variable {self.name!r} to be a finite range, "
                    f"got [{self.low!r}, {self.high!r}]."
                )
            if not lo < hi:
                what = "an empty" if lo == hi else "an inverted"
                raise ValueError(
                    f"Expected variable {self.name!r} to have low < high, got {what} range [{lo!r}, {hi!r}]."
                )
            object.__setattr__(self, "low", lo)
            object.__setattr__(self, "high", hi)
            object.__setattr__(self, "sigma", _unused_real(self.sigma, "sigma"))
        else:
            s = check_positive(self.sigma, "sigma")
            object.__setattr__(self, "sigma", s)
            object.__setattr__(self, "low", _unused_real(self.low, "low"))
            object.__setattr__(self, "high", _unused_real(self.high, "high"))

    def from_unit(self, u: np.ndarray) -> np.ndarray:
        """Map samples ``u`` in the open unit interval onto this variable (uniform or normal)."""
        if self.kind == "range":
            return self.low + (self.high - self.low) * u
        from scipy.stats import norm

        return self.sigma * norm.ppf(u)

    def as_dict(self) -> dict[str, Any]:
        """The variable as plain JSON-ready data (``low``/``high`` or ``sigma`` by kind)."""
        d: dict[str, Any] = {
            "name": self.name,
            "kind": self.kind,
            "unit": self.unit,
            "description": self.description,
        }
        if self.kind == "range":
            d.update(low=self.low, high=self.high)
        else:
            d.update(sigma=self.sigma)
        return d


@dataclass(frozen=True)
class Metric:
    """One per-design output: ``shape`` is the trailing shape of its array (() for a scalar).

    Parameters
    ----------
    name : str
        A Python identifier, unique in the study and none of the store's reserved names.
    unit : str
        Unit label for reports (e.g. ``"m"``, ``"N m"``, ``""`` for dimensionless).
    description : str
        Free text for reports.
    shape : tuple of int, optional
        Trailing shape of the per-design value (each entry >= 1); default ``()``, a scalar.
    dtype : str, optional
        ``"float64"`` (default) or ``"bool"``.

    Raises
    ------
    ValueError
        If ``name`` is not an identifier, ``unit`` / ``description`` are not str, ``shape`` is not a
        tuple of positive ints, or ``dtype`` is unknown.
    """

    name: str
    unit: str
    description: str
    shape: tuple[int, ...] = ()
    dtype: str = "float64"

    def __post_init__(self) -> None:
        if not isinstance(self.name, str) or not self.name.isidentifier():
            raise ValueError(f"Expected name to be an identifier (a metric name), got {self.name!r}.")
        _check_text(self.unit, "unit")
        _check_text(self.description, "description")
        if not isinstance(self.shape, tuple):
            raise ValueError(f"Expected shape to be a tuple of ints, got {type(self.shape).__name__}.")
        for d in self.shape:
            check_int(d, "shape", low=1)
        check_choice(self.dtype, "dtype", ("float64", "bool"))


@dataclass(frozen=True)
class Objective:
    """A metric to optimise: ``sense`` is ``"max"`` or ``"min"``.

    Parameters
    ----------
    metric : str
        Name of a scalar metric of the study.
    sense : str
        ``"max"`` or ``"min"``.

    Raises
    ------
    ValueError
        If ``metric`` is not a str or ``sense`` is neither ``"max"`` nor ``"min"``.
    """

    metric: str
    sense: str

    def __post_init__(self) -> None:
        if not isinstance(self.metric, str):
            raise ValueError(f"Expected metric to be a metric name (str), got {type(self.metric).__name__}.")
        check_choice(self.sense, "sense", ("max", "min"))


# evaluate(study, params, rows, seed) -> {metric name: array (n, *shape)} for the n designs of one chunk;
# ``params`` is a list of parameter objects (None where the dataclass rejected the design).
Evaluator = Callable[["DesignStudy", list[Any], np.ndarray, np.random.SeedSequence], dict[str, np.ndarray]]


@dataclass(frozen=True)
class DesignStudy:
    """A registered design study.

    ``nominal`` builds the nominal parameter object; ``variables`` the default design variables;
    ``metrics`` what ``evaluate`` returns; ``objectives`` the Pareto/NSGA-II objectives;
    ``parameters`` the study's fixed settings (pose grids, motions), stored in the results;
    ``poses_per_design`` the number of pose evaluations one design costs (for throughput figures);
    ``default_sampler`` / ``default_chunk`` the sampling method and chunk size (designs per task).

    Parameters
    ----------
    name : str
        Registry name (e.g. ``"omnileg-synthesis"``).
    title : str
        Human-readable title.
    mechanism : str
        The mechanism subpackage it studies.
    nominal : callable
        ``nominal() -> parameter dataclass``: the nominal design.
    variables : tuple of Variable
        Default design variables (non-empty).
    metrics : tuple of Metric
        What ``evaluate`` returns (non-empty, unique names).
    evaluate : callable
        ``evaluate(study, params, rows (n, n_variables), seed) -> {metric name: (n, *shape)}``;
        ``params`` holds None where the dataclass rejected the design.
    parameters : mapping, optional
        Fixed settings (pose grids, motions), stored in the results.
    objectives : tuple of Objective, optional
        Pareto / NSGA-II objectives, each naming a metric.
    poses_per_design : int, optional
        Pose evaluations one design costs (>= 1; for throughput figures).
    default_sampler : str, optional
        ``"sobol"`` (default), ``"lhs"``, ``"grid"`` or ``"random"``.
    default_chunk : int, optional
        Designs per Dask task (>= 1).
    default_designs : int, optional
        Designs of a sweep when not given (>= 1).
    notes : tuple of str, optional
        Notes for the report.
    error_names : tuple of str, optional
        The names a ``kind="normal"`` variable may take (manufacturing errors).
    summarize : callable, optional
        ``summarize(study, results) -> list of tables`` for the report; None: none.

    Raises
    ------
    ValueError
        If a text field is not a str, a callable field is not callable, ``variables`` / ``metrics`` /
        ``objectives`` are not tuples of their class (or empty, or with duplicate or reserved metric
        names, or an objective names no metric), an int field is below 1, the sampler is unknown, or
        ``parameters`` is not a mapping.
    """

    name: str
    title: str
    mechanism: str
    nominal: Callable[[], Any]
    variables: tuple[Variable, ...]
    metrics: tuple[Metric, ...]
    evaluate: Evaluator
    parameters: Mapping[str, Any] = field(default_factory=dict)
    objectives: tuple[Objective, ...] = ()
    poses_per_design: int = 1
    default_sampler: str = "sobol"
    default_chunk: int = 64
    default_designs: int = 256
    notes: tuple[str, ...] = ()
    error_names: tuple[str, ...] = ()  # names a kind="normal" variable may take
    # summarize(study, results) -> list of {"title", "columns", "rows", "note"} tables for the report
    # (results: open_results of the store); study-level analyses such as a sensitivity ranking
    summarize: Callable[[DesignStudy, Mapping[str, Any]], list[dict[str, Any]]] | None = None

    def __post_init__(self) -> None:
        for n in ("name", "title", "mechanism"):
            _check_text(getattr(self, n), n)
        for n in ("notes", "error_names"):
            object.__setattr__(self, n, _check_texts(getattr(self, n), n))
        if self.summarize is not None and not callable(self.summarize):
            raise ValueError(
                f"Expected summarize to be callable or None, got {type(self.summarize).__name__}."
            )
        for n in ("nominal", "evaluate"):
            if not callable(getattr(self, n)):
                raise ValueError(f"Expected {n} to be callable, got {type(getattr(self, n)).__name__}.")
        for n, cls in (("variables", Variable), ("metrics", Metric), ("objectives", Objective)):
            items = getattr(self, n)
            if not isinstance(items, tuple) or not all(isinstance(x, cls) for x in items):
                raise ValueError(f"Expected {n} to be a tuple of {cls.__name__}, got {items!r}.")
        if not self.variables or not self.metrics:
            raise ValueError("Expected variables and metrics to be non-empty, got an empty tuple.")
        names = [m.name for m in self.metrics]
        reserved = {
            "designs",
            "design_ok",
            "chunk_done",
            "chunk_seconds",
            "chunk_cpu_seconds",
            "chunk_checksum",
            "report",
        } & set(names)
        if reserved or len(set(names)) != len(names):
            raise ValueError(f"Expected metrics with unique, unreserved names, got {names}.")
        for o in self.objectives:
            if o.metric not in names:
                raise ValueError(f"Expected objectives to name metrics among {names}, got {o.metric!r}.")
        # stored as plain ints (a NumPy integer would survive into JSON reports and equality)
        coerce_int_fields(self, ("poses_per_design", "default_chunk", "default_designs"), low=1)
        check_choice(self.default_sampler, "default_sampler", ("sobol", "lhs", "grid", "random"))
        if not isinstance(self.parameters, Mapping):
            raise ValueError(f"Expected parameters to be a mapping, got {type(self.parameters).__name__}.")

    @property
    def variable_names(self) -> tuple[str, ...]:
        """Names of the design variables, in order (the columns of the design matrix)."""
        return tuple(v.name for v in self.variables)

    def parameter_fields(self) -> tuple[str, ...]:
        """Field names of the nominal parameter dataclass (what a range variable may name)."""
        return tuple(f.name for f in dataclasses.fields(self.nominal()))

    def designs_to_params(self, rows: np.ndarray) -> list[Any]:
        """Parameter objects of each row (None where the dataclass refuses the design).

        A ``range`` variable sets its field; a ``normal`` variable that names a field adds its error to
        the nominal value (the as-built parameter); other ``normal`` variables are left to ``evaluate``.
        """
        base = self.nominal()
        fields = {f.name for f in dataclasses.fields(base)}
        idx = [
            (i, v.name, v.kind == "normal")
            for i, v in enumerate(self.variables)
            if v.kind == "range" or v.name in fields
        ]
        out: list[Any] = []
        for row in np.asarray(rows, dtype=float):
            if not idx:
                out.append(base)
                continue
            values = {
                name: float(getattr(base, name)) + float(row[i]) if err else float(row[i])
                for i, name, err in idx
            }
            try:
                out.append(dataclasses.replace(base, **values))
            except ValueError:
                out.append(None)  # the parameter dataclass rejects this combination: a failed design
        return out

    def evaluate_rows(self, rows: np.ndarray, seed: np.random.SeedSequence) -> dict[str, np.ndarray]:
        """Every metric for the designs ``rows (n, n_variables)``, plus ``design_ok (n,)``."""
        params = self.designs_to_params(rows)
        out = self.evaluate(self, params, np.asarray(rows, dtype=float), seed)
        ok = np.array([p is not None for p in params], dtype=bool)
        if "design_ok" in out:  # the study's own verdict (e.g. a description that cannot be built)
            ok &= np.asarray(out["design_ok"], dtype=bool)
        res = {"design_ok": ok}
        for m in self.metrics:
            a = np.asarray(out[m.name], dtype=m.dtype)
            expected = (len(params), *m.shape)
            if a.shape != expected:  # a study bug, not a user error
                raise RuntimeError(
                    f"study {self.name!r}: metric {m.name!r} has shape {a.shape}, not {expected}"
                )
            res[m.name] = a
        return res

    def describe(self) -> dict[str, Any]:
        """The study as plain JSON-ready data (stored in a sweep's attributes)."""
        return {
            "study": self.name,
            "title": self.title,
            "mechanism": self.mechanism,
            "variables": [v.as_dict() for v in self.variables],
            "metrics": [{"name": m.name, "unit": m.unit, "description": m.description} for m in self.metrics],
            "objectives": [{"metric": o.metric, "sense": o.sense} for o in self.objectives],
            "parameters": dict(self.parameters),
            "poses_per_design": self.poses_per_design,
        }


def _check_text(value: object, name: str) -> None:
    if not isinstance(value, str):
        raise ValueError(f"Expected {name} to be a str, got {type(value).__name__}.")


def _check_texts(value: object, name: str) -> tuple[str, ...]:
    """A sequence of str (not one str) as a tuple."""
    if isinstance(value, str | bytes) or not isinstance(value, Sequence):
        raise ValueError(f"Expected {name} to be a tuple of str, got {type(value).__name__}.")
    for v in value:
        _check_text(v, f"each of {name}")
    return tuple(value)


def _unused_real(value: object, name: str) -> float:
    """A field the variable's kind does not use: a real number, NaN (the default) for not given."""
    if isinstance(value, float) and math.isnan(value):
        return value
    return check_real(value, name, finite=False)


def check_variables(variables: object, name: str = "variables") -> tuple[Variable, ...]:
    """A sequence of Variable (not a str) as a tuple."""
    if isinstance(variables, str | bytes) or not isinstance(variables, Sequence):
        raise ValueError(f"Expected {name} to be a sequence of Variable, got {type(variables).__name__}.")
    if not all(isinstance(v, Variable) for v in variables):
        bad = next(type(v).__name__ for v in variables if not isinstance(v, Variable))
        raise ValueError(f"Expected {name} to be a sequence of Variable, got an element of type {bad}.")
    return tuple(variables)


def with_variables(study: DesignStudy, variables: Sequence[Variable]) -> DesignStudy:
    """The study with its variables replaced or extended by ``variables`` (validated).

    A ``range`` variable must name a field of the study's parameter dataclass; a ``normal`` variable must
    name one of the study's manufacturing errors.  An override of an existing variable keeps its unit
    and description when the override gives none.

    Parameters
    ----------
    study : DesignStudy
        The study to modify (unchanged: studies are frozen).
    variables : sequence of Variable
        Replacements (same name) or additions.

    Returns
    -------
    DesignStudy
        A copy with the new variables, existing ones in their order, new ones appended.

    Raises
    ------
    ValueError
        If ``study`` is not a DesignStudy, ``variables`` is not a sequence of Variable (or names a
        variable twice), a range
        variable names no parameter field (or names an error), a normal variable names no error, or an
        override changes a variable's kind.

    Examples
    --------
    >>> from robomech.explore import Variable, get_study, with_variables
    >>> study = get_study("omnileg-synthesis")
    >>> with_variables(study, [Variable("L3", 0.05, 0.1, unit="m")]).variable_names
    ('L1', 'L4', 'L5', 'L3')
    """
    if not isinstance(study, DesignStudy):
        raise ValueError(f"Expected study to be a DesignStudy, got {type(study).__name__}.")
    overrides = check_variables(variables, "variables")
    names = [v.name for v in overrides]
    if len(set(names)) != len(names):
        dup = sorted({x for x in names if names.count(x) > 1})
        raise ValueError(
            f"Expected variables to name each variable once, got {', '.join(dup)} more than once."
        )
    fields = study.parameter_fields()
    current = {v.name: v for v in study.variables}
    for ov in overrides:
        if ov.kind == "range":
            if study.error_names and ov.name in study.error_names:
                raise ValueError(
                    f"Expected variables to give a standard deviation for error {ov.name!r} of study "
                    f"{study.name!r} (NAME=SIGMA), got a range."
                )
            if ov.name not in fields:
                raise ValueError(
                    f"Expected variables to name fields of {type(study.nominal()).__name__}, got "
                    f"design variable {ov.name!r}, not a field; its fields are: {', '.join(fields)}."
                )
        elif ov.name not in study.error_names:
            raise ValueError(
                f"Expected variables to name study {study.name!r}'s manufacturing errors "
                f"({', '.join(study.error_names) or 'it has none'}), got error {ov.name!r}."
            )
        old = current.get(ov.name)
        if old is not None and old.kind != ov.kind:
            raise ValueError(f"Expected variables[{ov.name!r}] to be of kind {old.kind!r}, got {ov.kind!r}.")
        if old is not None:
            ov = dataclasses.replace(
                ov, unit=ov.unit or old.unit, description=ov.description or old.description
            )
        current[ov.name] = ov
    return dataclasses.replace(study, variables=tuple(current.values()))


def design_blocks(params: Sequence[Any], varied: Collection[str], size: int) -> Iterator[np.ndarray]:
    """Indices into ``params`` (parameter dataclasses; None, a rejected design, is skipped) in blocks of
    at most ``size`` designs equal in every field but ``varied``: the designs one broadcasting kernel call
    takes as per-design arrays (:class:`DesignArrays`).  Groups in first-seen order, indices ascending."""
    groups: dict[tuple[Any, ...], list[int]] = {}
    for i, p in enumerate(params):
        if p is not None:
            key = tuple(getattr(p, f.name) for f in dataclasses.fields(p) if f.name not in varied)
            groups.setdefault(key, []).append(i)
    for g in groups.values():
        for s in range(0, len(g), size):
            yield np.array(g[s : s + size], dtype=np.int64)


@dataclass(frozen=True)
class DesignArrays:
    """Designs of one parameter class from one :func:`design_blocks` block, in place of one parameter
    object for a mechanism's broadcasting kernels: a subclass defines the varied fields (and every
    property derived from them) as arrays with a leading design axis; any other attribute is the first
    design's."""

    designs: tuple[Any, ...]

    def __getattr__(self, name: str) -> Any:
        return getattr(self.designs[0], name)
