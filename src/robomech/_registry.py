"""Discovery of registered modules (studies ``STUDY``, verifications ``VERIFICATION``) and their extras.

A module ``<package>/<name>.py`` registers itself by defining the attribute; names starting with an
underscore are infrastructure.  Discovery needs no list to edit when a mechanism is added, and it
imports no optional engine: modules that need one (MuJoCo) import it on first use and declare it in
``requires``, which :func:`missing_requirements` checks without importing it.
"""

from __future__ import annotations

import importlib
import importlib.util
import pkgutil
from collections.abc import Iterable
from typing import TypeVar

__all__ = ["EXTRAS", "discover", "missing_requirements", "skip_reason"]

T = TypeVar("T")

# Optional top-level modules -> the pip extra of robomech that installs them.
EXTRAS = {
    "mujoco": "verify",
    "dask": "explore",
    "distributed": "explore",
    "zarr": "explore",
    "pymoo": "explore",
}


def discover(package: str, path: Iterable[str], attribute: str, kind: type[T]) -> dict[str, T]:
    """Every ``kind`` instance bound to ``attribute`` in the public modules of ``package``, by ``.name``."""
    found: dict[str, T] = {}
    for info in sorted(pkgutil.iter_modules(path), key=lambda m: m.name):
        if info.name.startswith("_"):
            continue
        module = importlib.import_module(f"{package}.{info.name}")
        obj = getattr(module, attribute, None)
        if isinstance(obj, kind):
            found[obj.name] = obj  # type: ignore[attr-defined]
    return found


def missing_requirements(requires: Iterable[str]) -> list[str]:
    """The names in ``requires`` that cannot be imported here (found without importing them)."""
    missing = []
    for name in requires:
        try:
            found = importlib.util.find_spec(name) is not None
        except (ImportError, ValueError):  # a broken or blocked installation counts as absent
            found = False
        if not found:
            missing.append(name)
    return missing


def skip_reason(requires: Iterable[str]) -> str | None:
    """``"install robomech[verify] (needs mujoco)"`` when a requirement is missing, else None."""
    missing = missing_requirements(requires)
    if not missing:
        return None
    extras = sorted({EXTRAS.get(m, m) for m in missing})
    return f"install robomech[{','.join(extras)}] (needs {', '.join(missing)})"
