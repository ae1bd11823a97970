"""``robomech export MECHANISM --mjcf FILE`` (issue 13): the MJCF of a described mechanism.

``MECHANISM`` is a paper mechanism with a multibody description (its ``to_multibody`` at the paper's
parameters: ``spherical-leg``, ``omnileg``, ``vectored-thrust``), a gallery mechanism (``four_bar``,
``delta``, ...) or a path to an MJCF file (read and written back through the description).  The file
loads in MuJoCo with visible geometry (``mb.to_mjcf``) and the description's inertias.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

__all__ = ["add_parser"]


def _cmd_export(args: argparse.Namespace) -> int:
    from robomech import multibody as mb
    from robomech.verify._generic import describe  # verify may import the mechanisms; cli may not

    try:
        mech = describe(args.mechanism)
    except ValueError as exc:
        print(f"robomech: {exc}", file=sys.stderr)
        return 2
    xml = mb.to_mjcf(mech)
    if args.mjcf in (None, "-"):
        print(xml)
    else:
        Path(args.mjcf).write_text(xml)
        print(f"wrote {args.mjcf} ({mech.name}: {len(mech.bodies)} bodies, {len(mech.closures)} closures)")
    return 0


def add_parser(sub) -> None:
    sp = sub.add_parser("export", help="write the MJCF of a described mechanism")
    sp.add_argument("mechanism", metavar="MECHANISM", help="paper mechanism, gallery name or MJCF file")
    sp.add_argument("--mjcf", default=None, metavar="FILE", help="output file (default: stdout)")
    sp.set_defaults(func=_cmd_export)
