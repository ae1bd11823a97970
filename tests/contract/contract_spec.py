"""The bad-input specification format of the contract suite (see README.md in this folder).

A spec file ``contract_specs*.py`` beside a module's tests (``tests/multibody/contract_specs.py``)
defines ``SPECS: dict[str, Spec | Exempt]`` keyed by the full dotted public name
(``"robomech.spatial.exp_so3"``).  ``test_contract.py`` discovers every public name and drives each
spec with bad inputs; ``tests/conftest.py`` also runs a folder's cases with ``pytest tests/<folder>``.
"""

from __future__ import annotations

import importlib
import importlib.util
import inspect
import pkgutil
import sys
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

HERE = Path(__file__).resolve().parent
TESTS = HERE.parent  # spec files live beside each module's tests: tests/<module>/contract_specs*.py
SPEC_GLOB = "contract_specs*.py"

NAN = float("nan")
INF = float("inf")

# Ready-made lists of bad scalar options (each value must raise ValueError naming the option).
BAD_REAL = (NAN, INF, -INF, None, "1.0", True, 1j, [1.0, 2.0])
BAD_POSITIVE = (*BAD_REAL, 0.0, -1.0)
BAD_NONNEGATIVE = (*BAD_REAL, -1.0)
BAD_INT = (None, "1", True, 1.5, NAN, 1j)
BAD_BOOL = ("yes", 1, None, 0.0)
BAD_STR = (None, 1, 1.5)


@dataclass(frozen=True)
class Spec:
    """The bad-input specification of one public callable.

    ``args``     one good call: keyword arguments (small batch, leading batch axis first).
    ``arrays``   array arguments -> number of core (trailing, non-batch) dimensions.  Each gets NaN,
                 +inf, -inf, complex, a wrong shape, a str and None (None only if it is not the
                 parameter's default); each must raise ValueError naming the argument.
    ``masked``   array arguments whose non-finite samples are flagged instead: NaN/inf at one sample
                 must give ``mask`` False at exactly that sample, the other samples unchanged (the
                 argument's batch shape must equal the result mask's shape).
    ``nan_rows`` array arguments that take the library's own failed samples (NaN rows, e.g. the ``q`` of
                 a non-converged ``forward_kinematics`` sample): a NaN at one sample must give NaN
                 (float) or False (bool) at exactly that sample of every result array with the
                 argument's batch shape, the other samples unchanged; ±inf and 1e300 still raise.
    ``mask``     the result's per-sample mask: attribute name, index into a returned tuple, or a
                 function of the result (e.g. ``lambda r: np.isfinite(r[1])``).
    ``params``   parameter-object arguments: None, a str and a foreign object must raise naming them.
    ``options``  scalar options -> bad values (use BAD_REAL, BAD_POSITIVE, BAD_INT, BAD_BOOL, ...).
    ``wrong_shapes``  bad shapes per array argument, replacing the default (last core dimension + 1);
                 ``()`` for an argument whose every shape is acceptable.
    ``call``     what to call (default: the public object itself) as ``call(**args)``.
    ``finite_result``  the good call's result must be finite wherever ``mask`` is true (or everywhere
                 without ``mask``); False for functions whose good output may be inf by design.
    ``slow``     mark the good call and its bad calls ``pytest.mark.slow``.
    ``empty_batch``  the good call with every array argument cut to an empty leading batch must
                 return (empty results), not raise; False where an array's leading axis is no batch.
    ``unbatched``  array arguments that carry no batch axis (every axis is core: ``weights (6,)``,
                 ``M (4, 4)``, a mechanism's ``screws (n, 6)``).  In a spec with two or more arrays every
                 other array must have a batch in ``args`` (more axes than its core): the suite then
                 gives one of them a batch that does not broadcast with the others' and expects a
                 ValueError naming it, the other argument and the shape.
    ``batch_core``  core dimensions for the batch tests where they differ from ``arrays`` (an argument
                 masked per element of its last axis: ``wheel_rate (..., 6)`` is masked per wheel, core 0,
                 but its batch is everything before the wheel axis, core 1).
    ``good_elsewhere``  for a call that takes minutes (a whole engine verification): the test file
                 that runs the good call; the contract suite then makes only the bad calls.
    """

    args: Mapping[str, Any]
    arrays: Mapping[str, int] = field(default_factory=dict)
    masked: tuple[str, ...] = ()
    nan_rows: tuple[str, ...] = ()
    mask: str | int | Callable[[Any], Any] | None = None
    params: tuple[str, ...] = ()
    options: Mapping[str, tuple[Any, ...]] = field(default_factory=dict)
    wrong_shapes: Mapping[str, tuple[tuple[int, ...], ...]] = field(default_factory=dict)
    call: Callable[..., Any] | None = None
    finite_result: bool = True
    slow: bool = False
    good_elsewhere: str = ""
    empty_batch: bool = True
    unbatched: tuple[str, ...] = ()
    batch_core: Mapping[str, int] = field(default_factory=dict)

    def __post_init__(self) -> None:
        if self.good_elsewhere and (self.masked or self.mask is not None):
            raise ValueError("a spec with good_elsewhere cannot check masks (they need the good call)")
        if self.good_elsewhere and not (HERE.parent.parent / self.good_elsewhere).exists():
            raise ValueError(f"good_elsewhere names a missing test file: {self.good_elsewhere}")
        for a in (*self.masked, *self.nan_rows):
            if a not in self.arrays:
                raise ValueError(f"masked argument {a!r} must also be listed in arrays")
        for a in (*self.unbatched, *self.batch_core):
            if a not in self.arrays:
                raise ValueError(f"unbatched / batch_core argument {a!r} must also be listed in arrays")
        if self.masked and self.mask is None:
            raise ValueError("a spec with masked arguments needs mask=")
        for a in (*self.arrays, *self.params, *self.options):
            if a not in self.args:
                raise ValueError(f"argument {a!r} needs a good value in args")

    def batched(self) -> tuple[str, ...]:
        """The array arguments that carry a leading batch (all of ``arrays`` but ``unbatched``)."""
        return tuple(a for a in self.arrays if a not in self.unbatched)

    def core(self, arg: str) -> int:
        """The number of core dimensions of ``arg`` for the batch tests."""
        return self.batch_core.get(arg, self.arrays[arg])


@dataclass(frozen=True)
class Exempt:
    """An explicit exemption: the name takes no input to validate (constant, result type, ...)."""

    reason: str

    def __post_init__(self) -> None:
        if len(self.reason.strip()) < 8:
            raise ValueError("an exemption needs a real reason")


# Reasons reused by many spec files.
RESULT_TYPE = Exempt("frozen result type: constructed only by the library's own functions")
CONSTANT = Exempt("module-level constant: no input")


def exempt(names: str, reason: Exempt | str, prefix: str = "") -> dict[str, Exempt]:
    """``exempt("A B C", RESULT_TYPE, "robomech.x.")`` -> the same exemption for several names."""
    e = reason if isinstance(reason, Exempt) else Exempt(reason)
    return {prefix + n: e for n in names.split()}


# --- discovery ------------------------------------------------------------------------------------
def public_modules() -> list[str]:
    """Every importable robomech module none of whose path components starts with an underscore."""
    import robomech

    names = ["robomech"]
    for m in pkgutil.walk_packages(robomech.__path__, "robomech."):
        if not any(p.startswith("_") for p in m.name.split(".")[1:]):
            names.append(m.name)
    return sorted(names)


def public_names() -> dict[str, object]:
    """``{"robomech.spatial.exp_so3": <function>, ...}`` over every public ``__all__`` (modules
    listed in an ``__all__`` are walked themselves, so they are not names to specify)."""
    out: dict[str, object] = {}
    for modname in public_modules():
        mod = importlib.import_module(modname)
        for n in getattr(mod, "__all__", ()):
            obj = getattr(mod, n)
            if inspect.ismodule(obj):
                continue
            out[f"{modname}.{n}"] = obj
    return out


def spec_files() -> list[Path]:
    """Every spec file: ``tests/**/contract_specs*.py`` (not in this folder), sorted."""
    return sorted(p for p in TESTS.rglob(SPEC_GLOB) if HERE not in p.parents and p.parent != HERE)


def load_spec_file(path: Path) -> dict[str, Spec | Exempt]:
    """The ``SPECS`` of one spec file (imported once per process under a name unique to its path)."""
    if str(HERE) not in sys.path:
        sys.path.insert(0, str(HERE))
    rel = path.resolve().relative_to(TESTS).with_suffix("")
    modname = "contract_specs__" + "__".join(rel.parts)
    if modname in sys.modules:
        mod = sys.modules[modname]
    else:
        spec = importlib.util.spec_from_file_location(modname, path)
        mod = importlib.util.module_from_spec(spec)
        sys.modules[modname] = mod
        spec.loader.exec_module(mod)
    return mod.SPECS


def load_specs() -> tuple[dict[str, Spec | Exempt], dict[str, str]]:
    """All specs of every spec file: (name -> spec, name -> defining file relative to ``tests/``).
    Duplicates raise."""
    specs: dict[str, Spec | Exempt] = {}
    where: dict[str, str] = {}
    for path in spec_files():
        rel = str(path.relative_to(TESTS))
        for key, value in load_spec_file(path).items():
            if key in specs:
                raise ValueError(f"{key} is specified twice: in {where[key]} and in {rel}")
            if not isinstance(value, Spec | Exempt):
                raise TypeError(f"{rel}: SPECS[{key!r}] must be a Spec or an Exempt")
            specs[key] = value
            where[key] = rel
    return specs, where


def spec_file_for(name: str) -> str:
    """The spec file a public name belongs in, beside its module's tests (relative to ``tests/``):
    ``robomech.analysis.lstsq.solve`` -> ``analysis/contract_specs.py``;
    ``robomech.mechanisms.omnileg.jacobian`` -> ``mechanisms/omnileg/contract_specs.py``;
    a top-level module without a test folder (``robomech.testing``) -> ``contract_specs_testing.py``."""
    parts = name.split(".")[1:-1]
    if not parts:
        return "contract_specs.py"
    folder = parts[:2] if parts[0] == "mechanisms" and len(parts) > 1 else parts[:1]
    if not (TESTS.joinpath(*folder)).is_dir():
        return f"contract_specs_{parts[0]}.py"
    return "/".join(folder) + "/contract_specs.py"
