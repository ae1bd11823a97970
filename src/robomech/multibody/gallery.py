"""Textbook mechanisms shipped as MJCF files (``robomech/multibody/gallery/*.xml``).

Each file's header comment states the mechanism, its dimensions, its reference configuration and the
known properties the tests check (docs/multibody.md shows them).
"""

from __future__ import annotations

from pathlib import Path

from ._model import Mechanism

__all__ = ["NAMES", "load", "path"]

_DIR = Path(__file__).resolve().parent / "gallery"
NAMES = tuple(sorted(p.stem for p in _DIR.glob("*.xml")))


def path(name: str) -> Path:
    """Path of the gallery MJCF file ``name`` (one of :data:`NAMES`)."""
    if name not in NAMES:
        raise ValueError(f"Expected a gallery name among {list(NAMES)}, got {name!r}.")
    return _DIR / f"{name}.xml"


def load(name: str) -> Mechanism:
    """The gallery mechanism ``name`` read with :func:`~robomech.multibody.from_mjcf` (needs MuJoCo)."""
    from ._mjcf import from_mjcf

    return from_mjcf(path(name))
