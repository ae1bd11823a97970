"""What a verification is: analytic model vs an independent engine or higher-fidelity model.

A module ``robomech/verify/<module>.py`` defines ``VERIFICATION = Verification(name=..., run=...)``;
``run()`` returns a list of :class:`Check`.  Each check names the quantity, the maximum error found,
the tolerance and *why* that tolerance (engine constraint stiffness, step size, model fidelity).
This layer is the only one that imports a multibody engine, and only on first use
(:func:`optional_module`): a verification that needs one declares it in ``requires`` and is skipped,
with the extra to install, where it is missing.
"""

from __future__ import annotations

import importlib
import json
import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from types import ModuleType
from typing import Any

import numpy as np

from robomech._registry import EXTRAS
from robomech._validation import check_bool, check_positive

__all__ = [
    "Check",
    "EngineUnavailable",
    "Tolerance",
    "Verification",
    "VerificationReport",
    "dumps_json",
    "optional_module",
    "to_jsonable",
]


class EngineUnavailable(ImportError):
    """An optional engine is needed but not installed; the message names the extra to install.

    An ``ImportError`` subclass, raised on first use of an :func:`optional_module` whose module is
    absent, e.g. ``mujoco is not installed; install it with: pip install 'robomech[verify]'``.

    Parameters
    ----------
    message : str
        The missing module and the ``pip install`` command of the extra that provides it.
    """


class _OptionalModule:
    """A module imported on first attribute access, so that importing its user costs nothing."""

    def __init__(self, name: str) -> None:
        self._name = name
        self._module: ModuleType | None = None

    def __getattr__(self, attr: str) -> Any:
        if attr.startswith("__") and attr.endswith("__"):
            raise AttributeError(attr)  # keep copy/pickle/inspect probes from importing the engine
        if self._module is None:
            try:
                self._module = importlib.import_module(self._name)
            except ImportError as e:
                extra = EXTRAS.get(self._name, self._name)
                raise EngineUnavailable(
                    f"{self._name} is not installed; install it with: pip install 'robomech[{extra}]'"
                ) from e
        return getattr(self._module, attr)

    def __repr__(self) -> str:
        state = "imported" if self._module is not None else "not yet imported"
        return f"<optional module {self._name!r} ({state})>"


def optional_module(name: str) -> Any:
    """A stand-in for ``import name`` that imports on first use.

    Parameters
    ----------
    name : str
        Top-level module name, e.g. ``"mujoco"``.

    Returns
    -------
    module-like
        Attribute access imports the module; if it is absent, :class:`EngineUnavailable` (an
        ``ImportError``) names the robomech extra that installs it.

    Examples
    --------
    >>> m = optional_module("no_such_engine_xyz")
    >>> m.step
    Traceback (most recent call last):
    ...
    robomech.verify._core.EngineUnavailable: no_such_engine_xyz is not installed; ...
    """
    if not isinstance(name, str) or not name.isidentifier():
        raise ValueError(f"Expected name to be a module name such as 'mujoco', got {name!r}.")
    return _OptionalModule(name)


def to_jsonable(obj: Any) -> Any:
    """Plain JSON types from numpy arrays and scalars, paths, tuples and dataclass-free containers.

    Non-finite floats become ``None`` (JSON ``null``): strict JSON has no NaN or infinity.

    Parameters
    ----------
    obj : object
        Nested dicts (keys become str), lists, tuples, sets, numpy arrays and scalars, str, int,
        float, bool, None and ``pathlib.Path`` (becomes str).

    Returns
    -------
    object
        The same structure in dict, list, str, int, float, bool and None only.

    Raises
    ------
    ValueError
        If ``obj`` holds a complex number or anything else not representable in JSON (a dataclass,
        say: convert it with its ``as_dict()`` first).

    Examples
    --------
    >>> import numpy as np
    >>> to_jsonable({"ok": np.bool_(True), "x": np.float64(0.5), "v": np.array([1.0, np.nan])})
    {'ok': True, 'x': 0.5, 'v': [1.0, None]}
    """
    if isinstance(obj, dict):
        return {str(k): to_jsonable(v) for k, v in obj.items()}
    if isinstance(obj, list | tuple | set | frozenset):
        return [to_jsonable(v) for v in obj]
    if isinstance(obj, np.ndarray | np.generic):
        return to_jsonable(obj.tolist())
    if isinstance(obj, bool | int | str) or obj is None:
        return obj
    if isinstance(obj, float):
        return obj if math.isfinite(obj) else None
    if isinstance(obj, Path):
        return str(obj)
    if isinstance(obj, complex):
        raise ValueError(f"Expected obj to hold real values only (JSON has no complex), got {obj!r}.")
    raise ValueError(
        f"Expected obj to hold JSON-representable values (dict, list, str, number, bool, None, numpy), "
        f"got {type(obj).__name__}: {obj!r}."
    )


def dumps_json(obj: Any, *, indent: int | None = 2) -> str:
    """Strict JSON text (``allow_nan=False``) of :func:`to_jsonable` of ``obj``.

    Parameters
    ----------
    obj : object
        Anything :func:`to_jsonable` accepts.
    indent : int, optional
        Indentation (>= 0; default 2); None for one line.

    Returns
    -------
    str
        The JSON text (non-ASCII characters kept).

    Raises
    ------
    ValueError
        If ``indent`` is not None or a non-negative int, or ``obj`` is not JSON-representable.

    Examples
    --------
    >>> import numpy as np
    >>> dumps_json({"passed": np.bool_(False), "error": float("inf")}, indent=None)
    '{"passed": false, "error": null}'
    """
    if indent is not None and (isinstance(indent, bool) or not isinstance(indent, int) or indent < 0):
        raise ValueError(f"Expected indent to be None or a non-negative int, got {indent!r}.")
    return json.dumps(to_jsonable(obj), indent=indent, allow_nan=False, ensure_ascii=False)


@dataclass(frozen=True)
class Tolerance:
    """A named tolerance with its reason; ``relative`` says how the error was normalised.

    Parameters
    ----------
    value : float
        The bound on the error (> 0), in the units of the checked quantity (or dimensionless when
        ``relative``).
    reason : str
        Why this value (engine constraint stiffness, step size, model fidelity); non-empty.
    relative : bool, optional
        The error is relative (normalised by the quantity's scale); default False (absolute).

    Raises
    ------
    ValueError
        If ``value`` is not positive and finite, ``reason`` is empty, or ``relative`` is not a bool.
    """

    value: float
    reason: str
    relative: bool = False

    def __post_init__(self) -> None:
        object.__setattr__(self, "value", check_positive(self.value, "value"))
        if not isinstance(self.reason, str) or not self.reason.strip():
            raise ValueError(f"Expected reason to be a non-empty str (why this value), got {self.reason!r}.")
        object.__setattr__(self, "relative", check_bool(self.relative, "relative"))


# What a check that is neither passed nor failed says instead (Check.verdict).
NOT_JUDGED = ("n/a", "inconclusive")


@dataclass(frozen=True)
class Check:
    """One comparison of a model quantity against an independent engine or model.

    Parameters
    ----------
    mechanism : str
        The mechanism verified (e.g. ``"omnileg"``).
    quantity : str
        What was compared (e.g. ``"forward kinematics, foot position"``).
    max_error : float
        The largest error found, in the quantity's units (or relative, as ``tolerance`` says); NaN
        or inf fails the check.
    tolerance : Tolerance
        The bound and its reason.
    detail : str, optional
        Free text (sample counts, where the maximum occurred).
    verdict : str, optional
        ``""`` (default): judged by the tolerance, pass or FAIL.  ``"n/a"``: the quantity does not
        apply to this mechanism (it would be 0 by construction, e.g. the closure of an open chain);
        ``"inconclusive"``: too little could be compared.  Either is neither passed nor failed.
    note : str, optional
        A remark the report prints under the check whatever its result (a comparison cut short, why a
        check does not apply).

    Raises
    ------
    ValueError
        If ``verdict`` is not one of ``""``, ``"n/a"``, ``"inconclusive"``.

    Examples
    --------
    >>> from robomech.verify import Check, Tolerance
    >>> c = Check("demo", "tip position (m)", 2e-9, Tolerance(1e-6, "engine constraint stiffness"))
    >>> c.passed, c.status, c.as_dict()["tolerance"]
    (True, 'pass', 1e-06)
    >>> Check("demo", "closure", 0.0, Tolerance(1e-9, "rounding"), verdict="n/a").status
    'n/a'
    """

    mechanism: str
    quantity: str
    max_error: float
    tolerance: Tolerance
    detail: str = ""
    verdict: str = ""
    note: str = ""

    def __post_init__(self) -> None:
        if self.verdict not in (*NOT_JUDGED, ""):
            raise ValueError(f"Expected verdict to be one of '', {NOT_JUDGED}, got {self.verdict!r}.")

    @property
    def passed(self) -> bool:
        """Judged (no ``verdict``), ``max_error`` finite and at most ``tolerance.value``."""
        return not self.verdict and math.isfinite(self.max_error) and self.max_error <= self.tolerance.value

    @property
    def failed(self) -> bool:
        """Judged (no ``verdict``) and not passed: an n/a or inconclusive check has not failed."""
        return not self.verdict and not self.passed

    @property
    def status(self) -> str:
        """``"pass"``, ``"FAIL"``, or the ``verdict`` (``"n/a"``, ``"inconclusive"``)."""
        return self.verdict or ("pass" if self.passed else "FAIL")

    def as_dict(self) -> dict[str, Any]:
        """Plain Python types only (numpy scalars converted; a non-finite error becomes None)."""
        err = float(self.max_error)
        return {
            "mechanism": str(self.mechanism),
            "quantity": str(self.quantity),
            "max_error": err if math.isfinite(err) else None,
            "tolerance": float(self.tolerance.value),
            "relative": bool(self.tolerance.relative),
            "reason": str(self.tolerance.reason),
            "passed": bool(self.passed),
            "status": self.status,
            "detail": str(self.detail),
            "note": str(self.note),
        }


@dataclass(frozen=True)
class Verification:
    """A registered verification: what ``robomech/verify/<module>.py`` defines as ``VERIFICATION``.

    Parameters
    ----------
    name : str
        Mechanism name, the key of :func:`available_verifications`.
    title : str
        Human-readable title.
    engine : str
        The independent engine or model compared against (e.g. ``"MuJoCo"``).
    run : callable
        ``run() -> sequence of Check``; imports its engine on first use only.
    requires : tuple of str, optional
        Optional modules the run needs (e.g. ``("mujoco",)``); where one is missing the verification
        is skipped with the extra to install.
    """

    name: str
    title: str
    engine: str
    run: Callable[[], Sequence[Check]]
    # optional modules the run needs (e.g. ("mujoco",)); missing ones skip it with the extra to install
    requires: tuple[str, ...] = ()


@dataclass
class VerificationReport:
    """The result of :func:`run_verifications`.

    Attributes
    ----------
    checks : list of Check
        Every check of the verifications that ran.
    skipped : list of tuple of str
        ``(mechanism, reason)`` of the verifications that could not run here (an engine not
        installed; ``reason`` names the extra).

    Examples
    --------
    >>> from robomech.verify import Check, Tolerance, VerificationReport
    >>> r = VerificationReport([Check("demo", "q", 1e-9, Tolerance(1e-6, "why"))])
    >>> r.passed, r.table().splitlines()[-1]
    (True, '1 passed, 0 failed')
    """

    checks: list[Check] = field(default_factory=list)
    # (mechanism, reason) of verifications that could not run here, e.g. the engine is not installed
    skipped: list[tuple[str, str]] = field(default_factory=list)

    @property
    def passed(self) -> bool:
        """No check that ran failed (skipped verifications are listed, n/a and inconclusive checks
        counted, not failed)."""
        return not any(c.failed for c in self.checks)

    def as_dict(self) -> dict[str, Any]:
        """``passed``, every check's :meth:`Check.as_dict` and the skipped ones, as plain data."""
        return {
            "passed": self.passed,
            "checks": [c.as_dict() for c in self.checks],
            "skipped": [{"mechanism": n, "reason": r} for n, r in self.skipped],
        }

    def table(self) -> str:
        """A plain-text table: one line per check (error, tolerance, pass/FAIL/n/a/inconclusive; a
        failure's detail and any check's note on the next lines), skips and counts."""
        wq = max([len("quantity"), *(len(c.quantity) for c in self.checks)])
        wm = max([len("mechanism"), *(len(c.mechanism) for c in self.checks)])
        header = f"{'mechanism':<{wm}} {'quantity':<{wq}} {'max error':>11} {'tolerance':>11}      result"
        lines = [header, "-" * len(header)]
        for c in self.checks:
            kind = " rel" if c.tolerance.relative else ""
            lines.append(
                f"{c.mechanism:<{wm}} {c.quantity:<{wq}} {c.max_error:>11.3e} "
                f"{c.tolerance.value:>11.1e}{kind:4}  {c.status}"
            )
            if c.failed and c.detail:  # a failure says why under its line
                lines.append(f"{'':<{wm}}   why: {c.detail}")
            if c.note:
                lines.append(f"{'':<{wm}}  note: {c.note}")
        n_pass = sum(c.passed for c in self.checks)
        n_fail = sum(c.failed for c in self.checks)
        lines += [f"skipped: {n} — {r}" for n, r in self.skipped]
        tail = "".join(
            f", {n} {v}" for v in NOT_JUDGED if (n := sum(c.verdict == v for c in self.checks))
        ) + (f", {len(self.skipped)} skipped" if self.skipped else "")
        lines.append(f"{n_pass} passed, {n_fail} failed{tail}")
        return "\n".join(lines)
