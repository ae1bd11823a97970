"""Discovery of registered modules: studies (``STUDY``) and verifications (``VERIFICATION``).

A module ``<package>/<name>.py`` registers itself by defining the attribute; names starting with an
underscore are infrastructure.  Discovery needs no list to edit when a mechanism is added.
"""

from __future__ import annotations

import importlib
import pkgutil
from collections.abc import Iterable
from typing import TypeVar

__all__ = ["discover"]

T = TypeVar("T")


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
