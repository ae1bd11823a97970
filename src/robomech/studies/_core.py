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

from robomech._progress import LOGGER, close_bar, open_bar

__all__ = [
    "Figure",
    "Printed",
    "Progress",
    "Study",
    "StudyResult",
    "Table",
    "comparison_table",
]

T = TypeVar("T")


@dataclass(frozen=True)
class Table:
    """A table of the report; cells are numbers or text (numbers are formatted by the writer).

    Parameters
    ----------
    title : str
        Table title.
    columns : sequence of str
        Column headers (units belong in the header or a unit column).
    rows : sequence of sequence
        One sequence of cells per row, each as long as ``columns``.
    note : str, optional
        Text shown under the table.

    Raises
    ------
    ValueError
        If a row does not have one cell per column.
    """

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
    """A PNG written by the study into its output folder; ``alt`` (default: the caption) for readers.

    Parameters
    ----------
    path : pathlib.Path
        The image file, inside the study's output folder.
    caption : str
        Caption shown under the figure.
    alt : str, optional
        Alternative text; empty (default): the caption.
    """

    path: Path
    caption: str
    alt: str = ""


@dataclass(frozen=True)
class Printed:
    """A value as the paper printed it: ``text`` is shown verbatim, ``value`` is used for arithmetic.

    Examples
    --------
    >>> Printed.of(126.7305).text, Printed.of("1.50").text, Printed.of("1.50").value
    ('126.7305', '1.50', 1.5)
    """

    text: str
    value: float

    @classmethod
    def of(cls, printed: str | float) -> Printed:
        if isinstance(printed, Printed):
            return printed
        if isinstance(printed, str):
            return cls(printed.strip(), float(printed))
        if isinstance(printed, int | np.integer):
            return cls(str(int(printed)), float(printed))
        # repr is the shortest string that round-trips: the literal as typed from the paper
        return cls(repr(float(printed)), float(printed))

    def __float__(self) -> float:
        return self.value

    def __str__(self) -> str:
        return self.text


@dataclass
class StudyResult:
    """Everything a study reports: prose, tables, figures and machine-readable data.

    Returned by a :class:`Study`'s ``run``; the report writer turns it into ``report.md``,
    ``report.html`` and ``results.json``.

    Attributes
    ----------
    name : str
        The study's name.
    title : str
        Report title.
    source : str
        The paper (or other source) it reproduces.
    summary : str
        Prose at the top of the report.
    tables : list of Table
        The report's tables, in order.
    figures : list of Figure
        The figures written into the output folder, in order.
    data : dict
        Machine-readable results for ``results.json`` (anything :func:`robomech.verify.to_jsonable`
        accepts; units in the keys or alongside).
    notes : list of str
        Remarks listed at the end (departures from the paper, choices made).
    """

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
    """A registered paper reproduction: ``run(out_dir, progress)`` returns a :class:`StudyResult`.

    What ``robomech/studies/<module>.py`` defines as ``STUDY``.

    Parameters
    ----------
    name : str
        Registry name, the key of :func:`available_studies`.
    title : str
        Human-readable title.
    source : str
        The paper (or other source) it reproduces.
    run : callable
        ``run(out_dir: pathlib.Path, progress: Progress) -> StudyResult``; writes its figures into
        ``out_dir``.
    requires : tuple of str, optional
        Optional modules the run needs (e.g. ``("mujoco",)``); missing ones skip it with the extra to
        install.
    """

    name: str
    title: str
    source: str
    run: Callable[[Path, Progress], StudyResult]
    # optional modules the run needs (e.g. ("mujoco",)); missing ones skip it with the extra to install
    requires: tuple[str, ...] = ()


def comparison_table(
    title: str,
    rows: Iterable[tuple[str, str | float | None, float, str]],
    *,
    note: str = "",
) -> Table:
    """Printed value, robomech's value and their difference side by side.

    ``rows`` are ``(quantity, printed, robomech, unit)``; ``printed`` may be ``None`` where the paper
    gives no number.  The printed value is shown exactly as given (a string such as ``"1.50"`` keeps
    its digits; a float is shown by its shortest round-trip form, i.e. as typed from the paper).

    Parameters
    ----------
    title : str
        Table title.
    rows : iterable of tuple
        ``(quantity: str, printed: str or float or None, robomech: float, unit: str)``.
    note : str, optional
        Text shown under the table.

    Returns
    -------
    Table
        Columns quantity, unit, paper (printed), robomech, difference (robomech - printed, in
        ``unit``) and relative (``|difference| / |printed|``; a dash where the printed value is
        missing or zero).

    Raises
    ------
    ValueError
        If ``title`` is not a str, ``rows`` is not an iterable of 4-tuples, a printed text is not a
        number, or a value is not a real number.

    Examples
    --------
    >>> from robomech.studies import comparison_table
    >>> t = comparison_table("demo", [("length", "1.50", 1.5, "m")])
    >>> [str(c) for c in t.rows[0]]
    ['length', 'm', '1.50', '1.5', '0.0', '0.0']
    """
    if not isinstance(title, str):
        raise ValueError(f"Expected title to be a str, got {type(title).__name__}.")
    if isinstance(rows, str) or not isinstance(rows, Iterable):
        raise ValueError(f"Expected rows to be an iterable of 4-tuples, got {rows!r}.")
    rows = list(rows)
    for i, row in enumerate(rows):
        if not isinstance(row, tuple | list) or len(row) != 4:
            raise ValueError(f"Expected rows[{i}] to be (quantity, printed, robomech, unit), got {row!r}.")
        if isinstance(row[1], str | Printed):  # the paper's digits as printed, e.g. "1.50"
            try:
                float(str(row[1]))
            except ValueError:
                raise ValueError(
                    f"Expected rows[{i}] printed value to be a number or its printed text, got {row[1]!r}."
                ) from None
        for value, what in ((row[1], "printed"), (row[2], "robomech")):
            if isinstance(value, str | Printed) and what == "printed":
                continue
            if (value is not None or what == "robomech") and (
                isinstance(value, bool) or not isinstance(value, numbers.Real)
            ):
                raise ValueError(f"Expected rows[{i}] {what} value to be a real number, got {value!r}.")
    out = []
    for quantity, printed, ours, unit in rows:
        if printed is None or not math.isfinite(float(printed)):
            out.append([quantity, unit, "—", ours, "—", "—"])
            continue
        p = Printed.of(printed)
        diff = float(ours) - p.value
        # relative difference is undefined against a printed zero: shown as a dash, not inf
        rel = abs(diff) / abs(p.value) if p.value != 0 else "—"
        out.append([quantity, unit, p, float(ours), diff, rel])
    return Table(
        title=title,
        columns=["quantity", "unit", "paper (printed)", "robomech", "difference", "relative"],
        rows=out,
        note=note,
    )


class Progress:
    """The progress of a study run: a ``rich`` bar on a terminal, log lines otherwise.

    What a study's ``run(out_dir, progress)`` reports through.  The interface a study uses:

    - :meth:`plan` (optional, once, first): the names of the steps to come, so that the bar knows its
      length (without it the bar counts steps without a total);
    - :meth:`step` at the start of each step (``progress.step("Fig. 5: actuator forces")``);
    - :meth:`iter` around a long loop inside a step (a second bar, or about ten lines).

    Every step is logged at INFO level on the ``"robomech"`` logger.  When ``enabled``, each step is
    also printed on ``stream`` as ``[elapsed s] prefix message``; when, in addition, ``stream`` is
    stderr and the command line turned the bars on (``robomech._progress.show_bars``: stderr is
    a terminal, no ``--quiet``), a bar below those lines shows the steps done, the time and the step
    under way, until :meth:`close` (or the end of a ``with`` block).

    Parameters
    ----------
    prefix : str, optional
        Text put before every message (e.g. the study's name).
    enabled : bool, optional
        Print at all (default True).
    stream : file-like, optional
        Where to print (default ``sys.stderr``).

    Examples
    --------
    >>> import io
    >>> out = io.StringIO()
    >>> p = Progress("demo: ", stream=out)
    >>> p.plan(["mobility", "figures"])
    >>> p.step("mobility")
    >>> out.getvalue().rstrip().endswith("demo: mobility")
    True
    """

    def __init__(self, prefix: str = "", *, enabled: bool = True, stream=None) -> None:
        self.prefix = prefix
        self.enabled = enabled
        self.stream = stream if stream is not None else sys.stderr
        self._to_stderr = stream is None
        self._t0 = time.perf_counter()
        self._total: int | None = None
        self._done = 0
        self._bar: Any = None
        self._task: Any = None

    def __enter__(self) -> Progress:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()

    def plan(self, names: Sequence[str]) -> None:
        """Declare the steps to come (their number is the bar's length); call before the first step."""
        self._total = len(list(names))
        if self._bar is not None:
            self._bar.update(self._task, total=self._total)

    def step(self, message: str) -> None:
        """Start a step: print ``message`` with the elapsed time (s) and the prefix; advance the bar."""
        self.log(message)
        if self._bar is not None:
            self._bar.update(self._task, completed=self._done, stage=message)
        self._done += 1

    def log(self, message: str) -> None:
        """Print ``message`` like a step's line without counting it as a step (a start, a result)."""
        LOGGER.info("%s%s", self.prefix, message)  # the Python API's progress (logger "robomech")
        if not self.enabled:
            return
        line = f"[{time.perf_counter() - self._t0:7.1f} s] {self.prefix}{message}"
        bar = self._open()
        if bar is None:
            print(line, file=self.stream, flush=True)
        else:
            bar.console.print(line, highlight=False, markup=False)

    def iter(self, items: Sequence[T], label: str, every: int | None = None) -> Iterator[T]:
        """Yield ``items``: a second bar on a terminal, otherwise about ten lines along the way."""
        n = len(items)
        bar = self._open() if self.enabled else None
        if bar is None:
            every = every or max(1, n // 10)
            for i, item in enumerate(items):
                if i % every == 0:
                    self.step(f"{label} {i + 1}/{n}")
                yield item
            return
        LOGGER.info("%s%s: %d", self.prefix, label, n)
        task = bar.add_task(f"  {label}", total=n, stage="")
        try:
            for i, item in enumerate(items):
                bar.update(task, completed=i)
                yield item
        finally:
            bar.remove_task(task)

    def close(self) -> None:
        """Remove the bar from the terminal (the printed step lines stay)."""
        if self._bar is not None:
            close_bar(self._bar, self._task)
            self._bar = self._task = None

    def _open(self) -> Any:
        if self._bar is None and self._to_stderr:
            self._bar = open_bar()
            if self._bar is not None:
                label = self.prefix.rstrip(": ") or "study"
                self._task = self._bar.add_task(label, total=self._total, stage="")
        return self._bar
