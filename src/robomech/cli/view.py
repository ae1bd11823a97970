"""``robomech view MECHANISM [--port P] [--no-browser]``: the live 3-D viewer in the browser.

``MECHANISM`` is what ``robomech export`` takes: a paper mechanism with a multibody description
(``spherical-leg``, ``omnileg``, ``vectored-thrust``), a gallery name (``four_bar``, ``delta``, ...),
an MJCF file, or a URDF file when the installed robomech reads URDF (``mb.from_urdf``).  The page is
served on 127.0.0.1 only, until Ctrl-C.
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

from ._core import EXIT_INTERRUPTED, EXIT_OK, CliError, Command


def _port(text: str) -> int:
    try:
        port = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected a TCP port number, got {text!r}") from None
    if not 1 <= port <= 65535:
        raise argparse.ArgumentTypeError(f"expected a TCP port in 1..65535, got {port}")
    return port


def _add_arguments(p: argparse.ArgumentParser) -> None:
    p.add_argument(
        "mechanism", metavar="MECHANISM", help="paper mechanism, gallery name, MJCF file (or URDF file)"
    )
    p.add_argument("--port", type=_port, default=None, help="TCP port on 127.0.0.1 (default: a free one)")
    p.add_argument("--no-browser", action="store_true", help="do not open the page in a web browser")
    p.add_argument(
        "--site", default=None, help="output site of the singularity measures (default: the first)"
    )


def _describe(target: str):
    from robomech import multibody as mb
    from robomech.verify._generic import describe  # verify may import the mechanisms; cli may not

    if target.lower().endswith(".urdf"):
        from_urdf = getattr(mb, "from_urdf", None)
        if from_urdf is None:
            raise CliError(f"{target}: this robomech reads MJCF, not URDF (no multibody.from_urdf)")
        return from_urdf(Path(target))
    return describe(target)


def _description() -> str:
    from robomech import multibody as mb

    return (
        "Serve a live 3-D view of MECHANISM on http://127.0.0.1:PORT: one slider per actuated joint\n"
        "re-assembles it, the singularity measures of an output site update live, and a button\n"
        "downloads a screenshot.  Stop with Ctrl-C.\n\n"
        "MECHANISM: spherical-leg, omnileg, vectored-thrust (paper descriptions), "
        f"{', '.join(mb.gallery.NAMES)} (gallery), or an MJCF file."
    )


def _run(args: argparse.Namespace) -> int:
    try:
        mech = _describe(args.mechanism)
    except (ValueError, OSError) as exc:
        raise CliError(str(exc)) from exc
    from robomech import viewer

    try:
        v = viewer.view(mech, site=args.site, port=args.port, open_browser=not args.no_browser)
    except ValueError as exc:
        raise CliError(str(exc)) from exc
    except OSError as exc:  # the port is taken
        raise CliError(f"--port {args.port}: cannot serve ({exc.strerror or exc})") from exc
    if args.port is not None and v.port != args.port:
        v.stop()
        raise CliError(f"--port {args.port}: the port is in use")
    print(
        f"robomech view: {mech.name} ({len(mech.bodies)} bodies, {len(mech.actuated)} actuated) "
        f"on {v.url} (Ctrl-C to stop)",
        flush=True,
    )
    try:
        while not v.stopped:
            time.sleep(0.2)
    except KeyboardInterrupt:
        print("robomech view: stopped", file=sys.stderr)
        return EXIT_INTERRUPTED
    finally:
        v.stop()
    return EXIT_OK


COMMAND = Command(
    name="view",
    help="show a mechanism in 3-D in the browser, with a slider per actuated joint",
    add_arguments=_add_arguments,
    run=_run,
    description=_description,
)
