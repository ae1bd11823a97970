"""What a study is and what it returns.

A study is a module ``robomech/studies/<name>.py`` that defines ``STUDY = Study(...)``.  Its ``run``
function receives the study's output folder and a :class:`Progress`, writes its figures there, and
returns a :class:`StudyResult`; :mod:`robomech.studies._report` turns that into ``report.md``,
``report.html`` and ``results.json``.  The registry discovers study modules, so a new study needs no
edit anywhere else.
"""

from __future__ import annotations

import math
import numbers
import sys
import time
from collections.abc import Callable, Iterable, Iterator, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, TypeVar

import numpy as np

__all__ = [
    "Figure",
    "Progress",
    "Study",
    "StudyResult",
    "Table",
    "comparison_table",
]

T = TypeVar("T")


@dataclass(frozen=True)
class Table:
    """A table of the report; cells are numbers or text (numbers are formatted by the writer)."""

    title: str
    columns: Sequence[str]
    rows: Sequence[Sequence[Any]]
    note: str = ""

    def __post_init__(self) -> None:
        for i, row in enumerate(self.rows):
            if len(row) != len(self.columns):
                raise ValueError(
                    f"Expected every row of table {self.title!r} to have {len(self.columns)} cells, "
                    f"got {len(row)} in row {i}."
                )


@dataclass(frozen=True)
class Figure:
    """A PNG written by the study into its output folder."""

    path: Path
    caption: str


@dataclass
class StudyResult:
    """Everything a study reports: prose, tables, figures and machine-readable data."""

    name: str
    title: str
    source: str
    summary: str = ""
    tables: list[Table] = field(default_factory=list)
    figures: list[Figure] = field(default_factory=list)
    data: dict[str, Any] = field(default_factory=dict)
    notes: list[str] = field(default_factory=list)


@dataclass(frozen=True)
class Study:
    name: str
    title: str
    source: str
    run: Callable[[Path, Progress], StudyResult]


def comparison_table(
    title: str,
    rows: Iterable[tuple[str, float | None, float, str]],
    *,
    note: str = "",
) -> Table:
    """Printed value, robomech's value and their difference side by side.

    ``rows`` are ``(quantity, printed, robomech, unit)``; ``printed`` may be ``None`` where the paper
    gives no number.
    """
    if not isinstance(title, str):
        raise ValueError(f"Expected title to be a str, got {type(title).__name__}.")
    if isinstance(rows, str) or not isinstance(rows, Iterable):
        raise ValueError(f"Expected rows to be an iterable of 4-tuples, got {rows!r}.")
    rows = list(rows)
    for i, row in enumerate(rows):
        if not isinstance(row, tuple | list) or len(row) != 4:
            raise ValueError(f"Expected rows[{i}] to be (quantity, printed, robomech, unit), got {row!r}.")
        for value, what in ((row[1], "printed"), (row[2], "robomech")):
            if (value is not None or what == "robomech") and (
                isinstance(value, bool) or not isinstance(value, numbers.Real)
            ):
                raise ValueError(f"Expected rows[{i}] {what} value to be a real number, got {value!r}.")
    out = []
    for quantity, printed, ours, unit in rows:
        if printed is None or not math.isfinite(float(printed)):
            out.append([quantity, unit, "—", ours, "—", "—"])
            continue
        diff = float(ours) - float(printed)
        # relative difference is undefined against a printed zero: shown as a dash, not inf
        rel = abs(diff) / abs(float(printed)) if float(printed) != 0 else "—"
        out.append([quantity, unit, float(printed), float(ours), diff, rel])
    return Table(
        title=title,
        columns=["quantity", "unit", "paper (printed)", "robomech", "difference", "relative"],
        rows=out,
        note=note,
    )


class Progress:
    """Progress lines on stderr for long runs; silent when ``enabled`` is false."""

    def __init__(self, prefix: str = "", *, enabled: bool = True, stream=None) -> None:
        self.prefix = prefix
        self.enabled = enabled
        self.stream = stream if stream is not None else sys.stderr
        self._t0 = time.perf_counter()

    def step(self, message: str) -> None:
        if self.enabled:
            elapsed = time.perf_counter() - self._t0
            print(f"[{elapsed:7.1f} s] {self.prefix}{message}", file=self.stream, flush=True)

    def iter(self, items: Sequence[T], label: str, every: int | None = None) -> Iterator[T]:
        """Yield ``items``, reporting about ten times along the way."""
        n = len(items)
        every = every or max(1, n // 10)
        for i, item in enumerate(items):
            if i % every == 0:
                self.step(f"{label} {i + 1}/{n}")
            yield item


def to_jsonable(obj: Any) -> Any:
    """Numpy arrays and scalars to plain JSON types (NaN/inf become strings, JSON has none)."""
    if isinstance(obj, dict):
        return {str(k): to_jsonable(v) for k, v in obj.items()}
    if isinstance(obj, list | tuple):
        return [to_jsonable(v) for v in obj]
    if isinstance(obj, np.ndarray):
        return to_jsonable(obj.tolist())
    if isinstance(obj, np.generic):
        return to_jsonable(obj.item())
    if isinstance(obj, float) and not math.isfinite(obj):
        return str(obj)
    if isinstance(obj, Path):
        return str(obj)
    return obj
