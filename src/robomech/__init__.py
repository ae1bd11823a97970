"""robomech: kinematics, dynamics and verification of robot mechanisms.

Layers (each imports only those above it; see docs/architecture.md):

    spatial -> kinematics, trajectory -> dynamics, analysis -> multibody -> viewer, mechanisms.<one per
            paper> -> explore -> verify -> studies -> cli

``import robomech`` is cheap: subpackages are imported on first use (``robomech.multibody`` works
without ``import robomech.multibody``), and ``dir(robomech)`` lists them.
"""

from __future__ import annotations

import importlib
from typing import Any

__version__ = "0.1.0"

_SUBPACKAGES = (
    "spatial",
    "kinematics",
    "trajectory",
    "dynamics",
    "analysis",
    "multibody",
    "viewer",
    "mechanisms",
    "explore",
    "verify",
    "studies",
    "cli",
    "testing",
)

__all__ = ["__version__", *_SUBPACKAGES]


def __getattr__(name: str) -> Any:
    if name in _SUBPACKAGES:
        return importlib.import_module(f"{__name__}.{name}")
    raise AttributeError(f"module 'robomech' has no attribute {name!r}")


def __dir__() -> list[str]:
    # the subpackages and the dunders, not this module's own imports (importlib, Any, annotations)
    return sorted({*__all__, *(n for n in globals() if n.startswith("__"))})
