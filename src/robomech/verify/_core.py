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

    Examples
    --------
    >>> from robomech.verify import Check, Tolerance
    >>> c = Check("demo", "tip position (m)", 2e-9, Tolerance(1e-6, "engine constraint stiffness"))
    >>> c.passed, c.as_dict()["tolerance"]
    (True, 1e-06)
    """

    mechanism: str
    quantity: str
    max_error: float
    tolerance: Tolerance
    detail: str = ""

    @property
    def passed(self) -> bool:
        """``max_error`` is finite and at most ``tolerance.value``."""
        return math.isfinite(self.max_error) and self.max_error <= self.tolerance.value

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
            "detail": str(self.detail),
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
        """Every check that ran passed (skipped verifications are listed, not failed)."""
        return all(c.passed for c in self.checks)

    def as_dict(self) -> dict[str, Any]:
        """``passed``, every check's :meth:`Check.as_dict` and the skipped ones, as plain data."""
        return {
            "passed": self.passed,
            "checks": [c.as_dict() for c in self.checks],
            "skipped": [{"mechanism": n, "reason": r} for n, r in self.skipped],
        }

    def table(self) -> str:
        """A plain-text table: one line per check (error, tolerance, pass/FAIL; a failure's detail on
        the next line), skips and counts."""
        wq = max([len("quantity"), *(len(c.quantity) for c in self.checks)])
        wm = max([len("mechanism"), *(len(c.mechanism) for c in self.checks)])
        header = f"{'mechanism':<{wm}} {'quantity':<{wq}} {'max error':>11} {'tolerance':>11}      result"
        lines = [header, "-" * len(header)]
        for c in self.checks:
            kind = " rel" if c.tolerance.relative else ""
            lines.append(
                f"{c.mechanism:<{wm}} {c.quantity:<{wq}} {c.max_error:>11.3e} "
                f"{c.tolerance.value:>11.1e}{kind:4}  {'pass' if c.passed else 'FAIL'}"
            )
            if not c.passed and c.detail:  # a failure says why under its line
                lines.append(f"{'':<{wm}}   why: {c.detail}")
        n_fail = sum(not c.passed for c in self.checks)
        lines += [f"skipped: {n} — {r}" for n, r in self.skipped]
        tail = f", {len(self.skipped)} skipped" if self.skipped else ""
        lines.append(f"{len(self.checks) - n_fail} passed, {n_fail} failed{tail}")
        return "\n".join(lines)
