"""Notebook display: compact reprs of result objects and a small picture of a mechanism.

A result holds arrays over a batch (``q (1000, 34)``); the dataclass repr prints them all.  The
compact repr shows each field's shape and dtype, a boolean mask as the count of True, a float
array's finite range, and scalars as they are; the dataclasses are otherwise unchanged (fields,
equality, ``dataclasses.replace``).  :func:`mechanism_png` draws :func:`robomech.multibody.draw`'s
wireframe on matplotlib's Agg canvas directly (``matplotlib.figure.Figure``, never pyplot), so
displaying a mechanism in Jupyter changes neither the backend nor the open figures.
"""

from __future__ import annotations

import dataclasses
import io

import numpy as np

__all__ = ["compact_repr", "install_compact_repr", "mechanism_png"]

# Side (in) and resolution of a mechanism's notebook picture: 3 in at 80 dpi is 240 x 240 px.
PNG_SIZE_IN = 3.0
PNG_DPI = 80


def _field(value: object) -> str:
    if isinstance(value, np.ndarray):
        if value.ndim == 0:
            return _field(value.item())
        if value.dtype == bool:
            return f"{int(np.count_nonzero(value))}/{value.size} True"
        shape = f"{value.dtype}{tuple(value.shape)}"
        if np.issubdtype(value.dtype, np.floating) and value.size:
            fin = value[np.isfinite(value)]
            if fin.size == 0:
                return f"{shape} all non-finite"
            rng = f"[{fin.min():.3g}, {fin.max():.3g}]"
            nonfinite = value.size - fin.size
            return f"{shape} in {rng}" + (f", {nonfinite} non-finite" if nonfinite else "")
        return shape
    if isinstance(value, float):
        return f"{value:.6g}"
    if dataclasses.is_dataclass(value) and not isinstance(value, type):
        return f"{type(value).__name__}(...)"
    text = repr(value)
    return text if len(text) <= 60 else text[:57] + "..."


def compact_repr(self: object) -> str:
    """``Name(field=float64(100, 34) in [-1, 2], converged=98/100 True, ...)``."""
    fields = ", ".join(f"{f.name}={_field(getattr(self, f.name))}" for f in dataclasses.fields(self))  # type: ignore[arg-type]
    return f"{type(self).__name__}({fields})"


def install_compact_repr(*classes: type) -> None:
    """Give each result dataclass the compact repr (its fields, equality and replace unchanged)."""
    for cls in classes:
        if not dataclasses.is_dataclass(cls):
            raise ValueError(f"Expected dataclasses, got {cls!r}.")
        cls.__repr__ = compact_repr  # type: ignore[method-assign]


def mechanism_png(mech: object) -> bytes:
    """A small PNG of ``mech``'s wireframe at its reference configuration (Agg canvas, no pyplot)."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    from ._draw import draw

    fig = Figure(figsize=(PNG_SIZE_IN, PNG_SIZE_IN), dpi=PNG_DPI)
    FigureCanvasAgg(fig)
    ax = fig.add_subplot(projection="3d")
    draw(mech, ax=ax)  # type: ignore[arg-type]
    ax.title.set_fontsize(9)
    for axis in (ax.xaxis, ax.yaxis, ax.zaxis):
        axis.label.set_fontsize(7)
    ax.tick_params(labelsize=6)
    buf = io.BytesIO()
    fig.savefig(buf, format="png")
    return buf.getvalue()
