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
from typing import Any

from ._core import EXIT_INTERRUPTED, EXIT_OK, CliError, Command, input_file, looks_like_file


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
    motion = p.add_mutually_exclusive_group()
    motion.add_argument(
        "--motion",
        metavar="FILE",
        default=None,
        help="play back configurations: a .npy of q (nt, nq), or a .npz with q and optionally t (s)",
    )
    motion.add_argument(
        "--simulate",
        metavar="SECONDS",
        type=float,
        default=None,
        help="simulate the passive motion under gravity from the reference pose and play it back",
    )


def _describe(target: str):
    from robomech import multibody as mb
    from robomech.verify._generic import describe  # verify may import the mechanisms; cli may not

    if looks_like_file(target):  # missing, a folder or malformed XML: one line with file:line
        input_file(target)
    if target.lower().endswith(".urdf"):
        from_urdf = getattr(mb, "from_urdf", None)
        if from_urdf is None:
            raise CliError(f"{target}: this robomech reads MJCF, not URDF (no multibody.from_urdf)")
        return from_urdf(Path(target))
    return describe(target)


def _geometry(target: str) -> Path | None:
    """The MJCF file whose geoms to draw: the file given, or a gallery mechanism's file."""
    from robomech import multibody as mb

    if target in mb.gallery.NAMES:
        return mb.gallery.path(target)
    if target.lower().endswith(".xml") and Path(target).is_file():
        return Path(target)
    return None


# Frames per second of a simulated motion's playback (its output times).
SIMULATE_FPS = 30.0


def _motion(args: argparse.Namespace, mech) -> tuple[Any, Any]:
    """The path to play back and its times: from --motion FILE, --simulate SECONDS, or none."""
    import numpy as np

    if args.motion is not None:
        try:
            data = np.load(args.motion)
        except (OSError, ValueError) as exc:
            raise CliError(f"--motion {args.motion}: cannot read it ({exc})") from exc
        if isinstance(data, np.ndarray):
            return data, None
        if "q" not in data:
            raise CliError(f"--motion {args.motion}: expected an array q (nt, nq) in the .npz")
        return data["q"], (data["t"] if "t" in data else None)
    if args.simulate is not None:
        from robomech import multibody as mb

        if not (np.isfinite(args.simulate) and args.simulate > 0):
            raise CliError(f"--simulate: expected a positive duration in seconds, got {args.simulate}")
        nt = max(2, round(args.simulate * SIMULATE_FPS) + 1)
        print(
            f"robomech view: simulating {args.simulate:g} s of {mech.name} ...", file=sys.stderr, flush=True
        )
        t0 = time.perf_counter()
        sim = mb.simulate(mech, mech.q0, np.zeros(len(mech.actuated)), np.linspace(0.0, args.simulate, nt))
        print(f"robomech view: simulated in {time.perf_counter() - t0:.1f} s", file=sys.stderr, flush=True)
        return sim, None
    return None, None


def _description() -> str:
    from robomech import multibody as mb

    return (
        "Serve a live 3-D view of MECHANISM on http://127.0.0.1:PORT: one slider per actuated joint\n"
        "re-assembles it, the singularity measures of an output site update live, and a button\n"
        "downloads a screenshot; --motion FILE or --simulate SECONDS adds a playback.  Stop with Ctrl-C.\n\n"
        "MECHANISM: spherical-leg, omnileg, vectored-thrust (paper descriptions), "
        f"{', '.join(mb.gallery.NAMES)} (gallery), or an MJCF file."
    )


def _run(args: argparse.Namespace) -> int:
    try:
        mech = _describe(args.mechanism)
    except (ValueError, OSError, ImportError) as exc:  # ImportError: MJCF without MuJoCo
        raise CliError(str(exc)) from exc
    from robomech import viewer

    path, times = _motion(args, mech)
    try:
        v = viewer.view(
            mech, site=args.site, port=args.port, open_browser=not args.no_browser,
            geometry=_geometry(args.mechanism), path=path, times=times,
        )  # fmt: skip
    except (ValueError, ImportError) as exc:  # ImportError: without the view extra (viser)
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
