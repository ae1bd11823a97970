"""robomech: kinematics, dynamics and verification of robot mechanisms.

Layers (each imports only those above it; see docs/architecture.md):

    spatial -> kinematics, trajectory -> dynamics, analysis -> multibody -> mechanisms.<one per paper>
            -> verify -> studies -> cli

``import robomech`` is cheap: subpackages are imported on first use.
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
    "mechanisms",
    "verify",
    "studies",
    "testing",
)

__all__ = ["__version__", *_SUBPACKAGES]


def __getattr__(name: str) -> Any:
    if name in _SUBPACKAGES:
        return importlib.import_module(f"{__name__}.{name}")
    raise AttributeError(f"module 'robomech' has no attribute {name!r}")
