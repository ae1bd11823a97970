"""The ``robomech`` command (also ``python -m robomech``).

Subcommands are discovered: every module ``robomech/cli/<module>.py`` that defines
``COMMAND = Command(...)`` (see :class:`robomech.cli._core.Command`) becomes ``robomech NAME``.

Exit codes
----------
0
    Success; every check that ran passed (checks skipped for a missing extra do not fail).
1
    A verification check ran and failed.
2
    Usage or input error (unknown name, bad ``--out``, bad arguments, a missing or malformed input
    file, an output path that cannot be written, an optional engine that is not installed): one line
    on stderr saying why.
3
    Internal error (a bug in robomech: please report it; ``--traceback`` shows where).
130
    Interrupted (Ctrl-C); completed study folders are kept, the interrupted one is discarded.
"""

from __future__ import annotations

import argparse
import os
import sys
import traceback
from collections.abc import Callable, Sequence
from typing import NoReturn

from robomech._registry import discover

from ._core import EXIT_INTERNAL, EXIT_INTERRUPTED, EXIT_USAGE, CliError, Command, missing_extra

__all__ = ["Command", "available_commands", "build_parser", "main"]


class _Parser(argparse.ArgumentParser):
    """An argument parser whose description may be computed when help is shown (listing names)."""

    lazy_description: Callable[[], str] | None = None

    def format_help(self) -> str:
        if self.lazy_description is not None:
            self.description = self.lazy_description()
            self.lazy_description = None
        return super().format_help()

    def error(self, message: str) -> NoReturn:
        """A usage error in one line (argparse would print the whole usage first), exit 2."""
        self.exit(EXIT_USAGE, f"{self.prog}: {message} (see {self.prog} --help)\n")


def available_commands() -> dict[str, Command]:
    """Every registered subcommand by name."""
    return discover(__name__, __path__, "COMMAND", Command)


def _version() -> str:
    from robomech import __version__

    return __version__


def build_parser() -> argparse.ArgumentParser:
    """The ``robomech`` argument parser with every registered subcommand."""
    p = _Parser(
        prog="robomech",
        description="Kinematics, dynamics and verification of robot mechanisms.",
        epilog="exit codes: 0 ok, 1 a check failed, 2 usage or input error, 3 internal error, "
        "130 interrupted. `robomech COMMAND --help` lists the names each command accepts.",
    )
    p.add_argument("--version", action="version", version=f"robomech {_version()}")
    p.add_argument("--traceback", action="store_true", help="on an internal error, show the traceback")
    sub = p.add_subparsers(dest="command", required=True, metavar="COMMAND", parser_class=_Parser)
    for name, cmd in available_commands().items():
        sp = sub.add_parser(name, help=cmd.help, description=cmd.help)
        if callable(cmd.description):
            sp.lazy_description = cmd.description
        elif cmd.description:
            sp.description = cmd.description
        sp.formatter_class = argparse.RawDescriptionHelpFormatter
        cmd.add_arguments(sp)
        sp.set_defaults(func=cmd.run)
    return p


def main(argv: Sequence[str] | None = None) -> int:
    """Run ``robomech`` with ``argv`` (default: ``sys.argv[1:]``) and return the exit code.

    Parameters
    ----------
    argv : sequence of str, optional
        The arguments after ``robomech``.

    Returns
    -------
    int
        0 ok, 1 a check failed, 2 usage or input error, 3 internal error, 130 interrupted.

    Examples
    --------
    >>> main(["verify", "no-such-mechanism"])  # the message goes to stderr
    2
    """
    if "matplotlib" not in sys.modules:
        # the command writes figures to files and shows none: matplotlib's Agg backend, chosen for
        # this process (and the workers it starts) here, never by a library import
        os.environ["MPLBACKEND"] = "agg"
    try:
        parser = build_parser()
        args = parser.parse_args(argv)  # exits 2 on a usage error, 0 after --help/--version
    except KeyboardInterrupt:
        print("robomech: interrupted", file=sys.stderr)
        return EXIT_INTERRUPTED
    try:
        return int(args.func(args))
    except CliError as e:
        print(f"robomech {args.command}: {e}", file=sys.stderr)
        return EXIT_USAGE
    except KeyboardInterrupt:
        print(f"robomech {args.command}: interrupted", file=sys.stderr)
        return EXIT_INTERRUPTED
    except BrokenPipeError:  # `robomech verify | head`: the reader left, not an error of ours
        sys.stderr.close()
        return 0
    except Exception as e:  # the last line of defence: an exit code, not a traceback
        hint = missing_extra(e)
        if hint is not None:  # an optional engine is not installed: the user's setup, not a bug
            print(f"robomech {args.command}: this needs an optional engine: {hint}", file=sys.stderr)
            return EXIT_USAGE
        if args.traceback:
            traceback.print_exc()
        print(
            f"robomech {args.command}: internal error: {type(e).__name__}: {e}\n"
            "This is a bug in robomech; please report it with the output of `robomech --traceback "
            f"{args.command} ...`.",
            file=sys.stderr,
        )
        return EXIT_INTERNAL
