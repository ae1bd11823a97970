"""``robomech export MECHANISM --mjcf FILE`` (issue 13): the MJCF of a described mechanism.

``MECHANISM`` is a paper mechanism with a multibody description (its ``to_multibody`` at the paper's
parameters: ``spherical-leg``, ``omnileg``, ``vectored-thrust``), a gallery mechanism (``four_bar``,
``delta``, ...) or a path to an MJCF file (read and written back through the description).  The file
loads in MuJoCo with visible geometry (``mb.to_mjcf``) and the description's inertias (bodies without
one get MuJoCo's inertia from the visual geoms).
"""

from __future__ import annotations

import argparse
from pathlib import Path

from ._core import EXIT_OK, CliError, Command


def _add_arguments(p: argparse.ArgumentParser) -> None:
    p.add_argument("mechanism", metavar="MECHANISM", help="paper mechanism, gallery name or MJCF file")
    p.add_argument("--mjcf", default=None, metavar="FILE", help="output file (default: stdout)")


def _run(args: argparse.Namespace) -> int:
    from robomech import multibody as mb
    from robomech.verify._generic import describe  # verify may import the mechanisms; cli may not

    try:
        mech = describe(args.mechanism)
    except (ValueError, OSError) as exc:
        raise CliError(str(exc)) from exc
    xml = mb.to_mjcf(mech)
    if args.mjcf in (None, "-"):
        print(xml)
    else:
        Path(args.mjcf).write_text(xml)
        print(f"wrote {args.mjcf} ({mech.name}: {len(mech.bodies)} bodies, {len(mech.closures)} closures)")
    return EXIT_OK


COMMAND = Command(
    name="export",
    help="write the MJCF of a described mechanism (paper description, gallery, MJCF file)",
    add_arguments=_add_arguments,
    run=_run,
)
