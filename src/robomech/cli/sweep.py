"""``robomech sweep``: design studies on Dask into a Zarr store (robomech.explore; docs/explore.md).

The subcommand itself lives in :mod:`robomech.cli._sweep` (``register(subparsers)`` adds its parser);
this module registers it like every other subcommand.
"""

from __future__ import annotations

import argparse
from typing import Any

from ._core import CliError, Command

# The extras `robomech sweep` needs beyond the core install (`robomech list` reports them too).
SWEEP_REQUIRES = ("distributed", "zarr")


class _OneParser:
    """Stands in for argparse's subparsers so that ``_sweep.register`` fills the parser it is given."""

    def __init__(self, parser: argparse.ArgumentParser) -> None:
        self.parser = parser

    def add_parser(self, name: str, **kwargs: Any) -> argparse.ArgumentParser:
        if kwargs.get("description"):
            self.parser.description = kwargs["description"]
        return self.parser


def _add_arguments(p: argparse.ArgumentParser) -> None:
    from ._sweep import register

    register(_OneParser(p))


def _run(args: argparse.Namespace) -> int:
    from robomech._registry import skip_reason

    from ._sweep import _cmd_sweep

    why = skip_reason(SWEEP_REQUIRES)
    if why:
        raise CliError(f"sweep cannot run here: {why}")

    return _cmd_sweep(args)


COMMAND = Command(
    name="sweep",
    help="design study (synthesis / tolerances) on Dask into a Zarr store",
    add_arguments=_add_arguments,
    run=_run,
)
