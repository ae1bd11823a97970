"""Progress of long operations, for the command line and for the Python API.

Every long operation reports its stages through :func:`stages`: each stage is logged at INFO level on
the ``"robomech"`` logger (a Python user sees them with ``logging.basicConfig(level=logging.INFO)``
or a handler on that logger), and, where the command line asked for it (:func:`show_bars`: stderr is
a terminal and ``--quiet`` was not given), drawn as a ``rich`` progress bar on stderr that is
removed when the operation ends.  Nothing is printed
otherwise: a library call is silent unless its caller configures logging.
"""

from __future__ import annotations

import logging
import sys
from collections.abc import Sequence
from typing import Any

LOGGER = logging.getLogger("robomech")

_BARS = {"enabled": False}


def show_bars(enabled: bool | None = None) -> bool:
    """Draw progress bars on stderr from now on (``None``: when stderr is a terminal); returns the
    setting.  The command line calls it once with ``not args.quiet``."""
    if enabled is None or enabled:
        isatty = getattr(sys.stderr, "isatty", None)
        enabled = bool(isatty and isatty())
    _BARS["enabled"] = bool(enabled)
    return _BARS["enabled"]


def bars_enabled() -> bool:
    """Whether :func:`show_bars` turned the bars on."""
    return _BARS["enabled"]


_LIVE: dict[str, Any] = {"bar": None, "users": 0}


def open_bar() -> Any:
    """The ``rich`` progress display on stderr (removed when its last user closes it), or ``None``
    when :func:`show_bars` did not turn the bars on.

    One display is shared by nested operations (a study step that runs a verification): each adds
    its own task (a line) and removes it when done, then calls :func:`close_bar`.  Tasks take a
    ``stage`` field: the text shown after the bar (the step under way).
    """
    if not bars_enabled():
        return None
    if _LIVE["bar"] is None:
        try:
            from rich.console import Console
            from rich.progress import BarColumn, MofNCompleteColumn, Progress, TextColumn, TimeElapsedColumn
        except ImportError:  # pragma: no cover - rich is a dependency
            return None
        bar = Progress(
            TextColumn("{task.description}"), BarColumn(), MofNCompleteColumn(), TimeElapsedColumn(),
            TextColumn("{task.fields[stage]}"),
            console=Console(stderr=True), transient=True,
        )  # fmt: skip
        bar.start()
        _LIVE["bar"] = bar
    _LIVE["users"] += 1
    return _LIVE["bar"]


def close_bar(bar: Any, task: Any) -> None:
    """Release the display of :func:`open_bar` and remove ``task`` from it; the last release draws
    it once more and removes it from the terminal."""
    if bar is None or bar is not _LIVE["bar"]:
        return
    _LIVE["users"] -= 1
    if _LIVE["users"] <= 0:
        bar.stop()
        _LIVE["bar"], _LIVE["users"] = None, 0
    else:
        bar.remove_task(task)


class Stages:
    """The named stages of one long operation; use as a context manager, call :meth:`next` per stage.

    Parameters
    ----------
    what : str
        The operation (``"verify continuum"``), the bar's label and the log messages' prefix.
    names : sequence of str
        The stages, in order (their number is the bar's length).
    """

    def __init__(self, what: str, names: Sequence[str]) -> None:
        self.what = what
        self.names = list(names)
        self.done = 0
        self._bar: Any = None

    def __enter__(self) -> Stages:
        LOGGER.info("%s: %d stages", self.what, len(self.names))
        self._bar = open_bar()
        if self._bar is not None:
            # until the first stage starts (models built, kernels compiled for first use): say so
            self._task = self._bar.add_task(self.what, total=len(self.names), stage="starting")
        return self

    def next(self, name: str | None = None) -> None:
        """Start the next stage (``name`` defaults to the one given at construction)."""
        label = name or (self.names[self.done] if self.done < len(self.names) else "")
        if self._bar is not None:
            self._bar.update(self._task, completed=self.done, stage=label)
        self.done += 1
        LOGGER.info("%s: [%d/%d] %s", self.what, self.done, len(self.names), label)

    def __exit__(self, *exc: object) -> None:
        if self._bar is not None:
            close_bar(self._bar, self._task)
            self._bar = None
        LOGGER.info("%s: done", self.what)


def stages(what: str, names: Sequence[str]) -> Stages:
    """The stages of a long operation (see :class:`Stages`)."""
    return Stages(what, names)
