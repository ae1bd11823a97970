"""``robomech export MECHANISM --mjcf FILE``: the MJCF of a described mechanism.

``MECHANISM`` is a paper mechanism with a multibody description (its ``to_multibody`` at the paper's
parameters: ``spherical-leg``, ``omnileg``, ``vectored-thrust``), a gallery mechanism (``four_bar``,
``delta``, ...) or a path to an MJCF or URDF file (read and written back through the description).  The file
loads in MuJoCo with visible geometry (``mb.to_mjcf``) and the description's inertias (bodies without
one get MuJoCo's inertia from the visual geoms).
"""

from __future__ import annotations

import argparse

from ._core import EXIT_OK, CliError, Command, did_you_mean, input_file, looks_like_file, output_file


def _add_arguments(p: argparse.ArgumentParser) -> None:
    p.add_argument("mechanism", metavar="MECHANISM", help="paper mechanism, gallery name, MJCF or URDF file")
    p.add_argument("--mjcf", default=None, metavar="FILE", help="output file (default: stdout)")


def _run(args: argparse.Namespace) -> int:
    from robomech import multibody as mb
    from robomech.verify._generic import _paper, describe  # verify may import the mechanisms; cli may not

    # every user mistake is found before any work: the output path, then the input
    out = None if args.mjcf in (None, "-") else output_file(args.mjcf)
    names = [*sorted(_paper()), *mb.gallery.NAMES]
    if args.mechanism not in names:
        if not looks_like_file(args.mechanism):
            raise CliError(
                f"unknown mechanism {args.mechanism!r}{did_you_mean(args.mechanism, names)}; valid ones are: "
                f"{', '.join(names)}, or an MJCF or URDF file"
            )
        input_file(args.mechanism)
    try:
        mech = describe(args.mechanism)
    except (ValueError, OSError) as exc:
        raise CliError(str(exc)) from exc
    xml = mb.to_mjcf(mech)
    if out is None:
        print(xml)
    else:
        try:
            out.write_text(xml)
        except OSError as exc:
            raise CliError(f"cannot write {args.mjcf!r}: {exc.strerror or exc}") from exc
        print(f"wrote {args.mjcf} ({mech.name}: {len(mech.bodies)} bodies, {len(mech.closures)} closures)")
    return EXIT_OK


COMMAND = Command(
    name="export",
    help="write the MJCF of a described mechanism (paper description, gallery, MJCF or URDF file)",
    add_arguments=_add_arguments,
    run=_run,
)
