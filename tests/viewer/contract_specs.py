"""Bad-input specs of robomech.viewer and of multibody's animate / view (the pictures of a mechanism)."""

import functools
import tempfile
from pathlib import Path

import numpy as np
from contract_spec import BAD_BOOL, BAD_INT, BAD_POSITIVE, BAD_STR, RESULT_TYPE, Exempt, Spec

from robomech import multibody as mb
from robomech import viewer

MECH = mb.gallery.load("four_bar")
Q = mb.forward_kinematics(MECH, np.array([[0.2], [-0.4], [0.6]])).q  # (3, 3) assembled frames
OUT = Path(tempfile.mkdtemp(prefix="robomech-animate-"))
BAD_PORT = (*(v for v in BAD_INT if v is not None), 0, -1, 70000)  # None: a free port


def _started_and_stopped(view):
    """The good call starts a server on 127.0.0.1: stop it at once (bad calls raise before it)."""

    @functools.wraps(view)  # the signature (q's default None) is the view's
    def call(**kwargs):
        v = view(**kwargs)
        v.stop()
        return v.pose

    return call


def _view_spec(view):
    return Spec(
        call=_started_and_stopped(view),
        args={"mech": MECH, "q": Q[0], "site": "coupler_point", "path": Q, "port": None,
              "open_browser": False, "geometry": mb.gallery.path("four_bar")},
        arrays={"q": 1},
        unbatched=("q",),  # one configuration
        params=("mech",),
        options={
            "site": (1, 1.5, "nope"),
            "path": ("x", np.zeros((3, 4)), np.zeros(3), 1j * Q),
            "port": BAD_PORT,
            "open_browser": BAD_BOOL,
            "geometry": (1, "no-such-file.xml", ""),
        },
        wrong_shapes={"q": ((2,), (2, 3))},
        finite_result=False,
        empty_batch=False,
    )  # fmt: skip


SPECS = {
    "robomech.viewer.view": _view_spec(viewer.view),
    "robomech.multibody.view": _view_spec(mb.view),
    "robomech.viewer.Viewer": Exempt(
        "the running viewer, constructed by view() (which validates); its set_q_act / set_q / "
        "screenshot validate their input (tests/viewer/test_viewer.py)"
    ),
    "robomech.viewer.Pose": RESULT_TYPE,
    "robomech.multibody.animate": Spec(
        args={
            "mech": MECH,
            "q": Q,
            "path": OUT / "four_bar.gif",
            "fps": 10.0,
            "title": "t",
            "site": "coupler_point",
            "times": np.array([0.0, 0.1, 0.2]),
            "dpi": 30,
            "size": 2.0,
            "view": (20.0, -60.0),
            "invert_z": False,
        },
        arrays={"q": 1},
        params=("mech",),
        options={
            "path": (None, 1, "motion.png", ""),
            "fps": BAD_POSITIVE,
            "title": BAD_STR,
            "site": (1, 1.5, "nope"),
            "times": ("x", np.zeros(2), np.array([0.0, np.nan, 0.2])),
            "dpi": (*BAD_INT, 0, 100000),
            "size": BAD_POSITIVE,
            "view": ("x", (1.0,), (np.nan, 0.0), [1.0, 2.0]),
            "invert_z": BAD_BOOL,
        },
        finite_result=False,
        empty_batch=False,
    ),
}
