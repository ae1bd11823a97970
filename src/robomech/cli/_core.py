"""What a subcommand is, the exit codes, and the checks every subcommand shares.

A subcommand is a module ``robomech/cli/<module>.py`` that defines ``COMMAND = Command(...)``; it is
discovered like studies and verifications, so adding one (``sweep``, ``export``) edits no other file.
Keep command modules cheap to import: import the library inside ``run``.
"""

from __future__ import annotations

import argparse
import difflib
import os
import sys
import tempfile
import time
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import Any

__all__ = [
    "EXIT_CHECK_FAILED",
    "EXIT_INTERNAL",
    "EXIT_INTERRUPTED",
    "EXIT_OK",
    "EXIT_USAGE",
    "CliError",
    "Command",
    "announce_compiles",
    "did_you_mean",
    "input_file",
    "missing_extra",
    "output_file",
    "output_folder",
]

EXIT_OK = 0  # everything ran and every check passed
EXIT_CHECK_FAILED = 1  # a check (verification) ran and failed
EXIT_USAGE = 2  # bad arguments or input (argparse uses 2 as well)
EXIT_INTERNAL = 3  # a bug: an unexpected exception inside robomech
EXIT_INTERRUPTED = 130  # SIGINT (128 + 2), the shell convention


class CliError(Exception):
    """A usage or input error: printed as one line on stderr, exit code ``EXIT_USAGE``."""


@dataclass(frozen=True)
class Command:
    """A ``robomech`` subcommand.

    Parameters
    ----------
    name : str
        The subcommand word (``robomech NAME ...``).
    help : str
        One line for ``robomech --help``.
    add_arguments : callable
        ``add_arguments(parser)`` adds the subcommand's arguments to its ``argparse`` parser.
    run : callable
        ``run(args) -> int`` returns the exit code; raise ``CliError`` for a usage error.
    description : str, optional
        Longer text for ``robomech NAME --help``; may be a callable returning it (evaluated when the
        parser is built, e.g. to list the registered names).
    """

    name: str
    help: str
    add_arguments: Callable[[argparse.ArgumentParser], None]
    run: Callable[[argparse.Namespace], int]
    description: str | Callable[[], str] = ""

    def __post_init__(self) -> None:
        if (
            not isinstance(self.name, str)
            or not self.name
            or self.name.strip() != self.name
            or " " in self.name
        ):
            raise ValueError(f"Expected name to be one word such as 'sweep', got {self.name!r}.")
        if not isinstance(self.help, str):
            raise ValueError(f"Expected help to be a str, got {type(self.help).__name__}.")
        for field_name in ("add_arguments", "run"):
            if not callable(getattr(self, field_name)):
                raise ValueError(
                    f"Expected {field_name} to be callable, got {type(getattr(self, field_name)).__name__}."
                )
        if not (isinstance(self.description, str) or callable(self.description)):
            raise ValueError(
                f"Expected description to be a str or a callable, got {type(self.description).__name__}."
            )


def output_folder(value: str) -> Path:
    """An ``--out`` folder that exists (created if needed) and is writable, or a ``CliError``.

    Rejects an empty path (it would silently mean the current directory), an existing non-folder, a
    path under a file, and a folder where a file cannot be created.
    """
    if not value or not value.strip():
        raise CliError("--out: expected a folder path, got an empty string")
    path = Path(value).expanduser()
    if path.exists() and not path.is_dir():
        raise CliError(f"--out: expected a folder, got an existing file {str(path)!r}")
    try:
        path.mkdir(parents=True, exist_ok=True)
    except FileExistsError as e:  # a parent is a file
        raise CliError(f"--out: cannot create folder {str(path)!r}: a parent is not a folder") from e
    except OSError as e:
        raise CliError(f"--out: cannot create folder {str(path)!r}: {e.strerror or e}") from e
    try:  # the real test: access() is wrong under some ACLs, root and read-only mounts
        fd, probe = tempfile.mkstemp(dir=path, prefix=".robomech-probe-")
        os.close(fd)
        os.unlink(probe)
    except OSError as e:
        raise CliError(f"--out: folder {str(path)!r} is not writable: {e.strerror or e}") from e
    return path


def output_file(value: str) -> Path:
    """An output file path whose folder exists and is writable, or a ``CliError`` with the reason.

    Rejects an empty path, an existing folder, a path whose folder is missing or not a folder, and a
    folder where a file cannot be created (``/proc``, a read-only mount).
    """
    if not value or not value.strip():
        raise CliError("expected an output file path, got an empty string")
    path = Path(value).expanduser()
    if path.is_dir():
        raise CliError(f"cannot write {str(path)!r}: it is a folder, expected a file path")
    parent = path.parent
    if not parent.exists():
        raise CliError(f"cannot write {str(path)!r}: no such folder {str(parent)!r}")
    if not parent.is_dir():
        raise CliError(f"cannot write {str(path)!r}: {str(parent)!r} is not a folder")
    try:  # the real test, as for --out: create (and remove) a file beside it
        fd, probe = tempfile.mkstemp(dir=parent, prefix=".robomech-probe-")
        os.close(fd)
        os.unlink(probe)
    except OSError as e:
        raise CliError(
            f"cannot write {str(path)!r}: no file can be created in {str(parent)!r} ({e.strerror or e})"
        ) from e
    return path


# Arguments that name a file rather than a registered or gallery name.
FILE_SUFFIXES = (".xml", ".mjcf", ".urdf")


def looks_like_file(arg: str) -> bool:
    """An argument meant as a file path: a known suffix, a path separator, or an existing file."""
    return arg.lower().endswith(FILE_SUFFIXES) or os.sep in arg or Path(arg).is_file()


def input_file(arg: str) -> Path:
    """An input file that exists and, for XML, parses; else a one-line ``CliError`` (``file:line``).

    The XML is parsed here (by the standard library) before a model compiler sees it, so a
    malformed file is reported as ``FILE:LINE:COLUMN: malformed XML (...)``, not in the compiler's words.
    """
    path = Path(arg).expanduser()
    if not path.exists():
        raise CliError(f"no such file: {arg}")
    if path.is_dir():
        raise CliError(f"expected a file, got the folder {arg}")
    if path.suffix.lower() in FILE_SUFFIXES:
        import xml.etree.ElementTree as ET

        try:
            ET.parse(path)
        except ET.ParseError as e:
            line, col = e.position
            reason = str(e).split(":")[0]
            raise CliError(f"{arg}:{line}:{col + 1}: malformed XML ({reason})") from e
        except UnicodeDecodeError as e:
            raise CliError(f"{arg}: not readable as text ({e.reason})") from e
        except OSError as e:
            raise CliError(f"cannot read {arg}: {e.strerror or e}") from e
    return path


def did_you_mean(name: str, choices: list[str] | tuple[str, ...]) -> str:
    """``" (did you mean 'omnileg'?)"`` for the closest of ``choices`` (difflib), or ``""``."""
    close = difflib.get_close_matches(name, list(choices), n=1, cutoff=0.6)
    return f" (did you mean {close[0]!r}?)" if close else ""


def missing_extra(exc: BaseException) -> str | None:
    """The install hint for an optional dependency that is not installed (``import mujoco`` failed).

    ``"install robomech[verify] (needs mujoco)"`` when ``exc``, or an exception it was raised from, is
    a ``ModuleNotFoundError`` of one of the optional packages of ``robomech._registry.EXTRAS``;
    ``None`` for anything else (a missing module of robomech itself is a bug).
    """
    from robomech._registry import EXTRAS

    seen: set[int] = set()
    e: BaseException | None = exc
    while e is not None and id(e) not in seen:  # also an ImportError re-raised "from" the missing module
        seen.add(id(e))
        if isinstance(e, ModuleNotFoundError) and e.name and e.name.split(".")[0] in EXTRAS:
            root = e.name.split(".")[0]
            return f"install robomech[{EXTRAS[root]}] (needs {root})"
        e = e.__cause__ or e.__context__
    return None


class _CompileNotice:
    """Prints one line on stderr when numba starts compiling a kernel (a cache miss), and its time."""

    def __init__(self) -> None:
        self.depth = 0
        self.t0 = 0.0
        self.enabled = True

    @property
    def stream(self) -> Any:
        return sys.stderr  # looked up at print time (redirections, pytest's capture)

    def on_start(self, event: Any) -> None:
        self.depth += 1
        if self.depth == 1 and self.enabled:  # nested compiles of callees belong to the same first use
            self.t0 = time.perf_counter()
            disp = (event.data or {}).get("dispatcher")
            name = getattr(getattr(disp, "py_func", None), "__qualname__", "a kernel")
            print(
                f"robomech: compiling {name} for first use (numba; cached on disk afterwards) ...",
                file=self.stream,
                flush=True,
            )

    def on_end(self, event: Any) -> None:
        self.depth -= 1
        if self.depth == 0 and self.enabled:
            seconds = time.perf_counter() - self.t0
            print(f"robomech: compiled in {seconds:.1f} s", file=self.stream, flush=True)


_NOTICE = _CompileNotice()
_INSTALLED = False


def announce_compiles(enabled: bool = True) -> bool:
    """Announce every numba compilation (a kernel's first use) on stderr from now on.

    Installed once per process; ``enabled=False`` silences it (``--quiet``).  Returns False if numba
    is not importable.
    """
    global _INSTALLED
    _NOTICE.enabled = enabled
    if _INSTALLED:
        return True
    try:
        from robomech._numba import import_numba

        import_numba()  # first, so that robomech's kernel cache location applies (see _numba)
        from numba.core import event
    except ImportError:  # pragma: no cover - numba is a dependency
        return False

    class _Listener(event.Listener):
        def on_start(self, ev: Any) -> None:
            _NOTICE.on_start(ev)

        def on_end(self, ev: Any) -> None:
            _NOTICE.on_end(ev)

    event.register("numba:compile", _Listener())
    _INSTALLED = True
    return True
