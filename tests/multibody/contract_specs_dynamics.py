"""Bad-input specs of the closed-chain dynamics of robomech.multibody (issue 13, multibody/_dynamics.py).

Kept beside specs/multibody.py (the kinematics layer's file) so the two helpers' files do not collide.
"""

import numpy as np
from contract_spec import BAD_BOOL, RESULT_TYPE, Spec, exempt

from robomech import multibody as mb

P = "robomech.multibody."
MECH = mb.gallery.load("four_bar")
QA = np.array([[0.2], [-0.4], [0.6]])
Q = mb.forward_kinematics(MECH, QA).q  # (3, 3)
QD = np.array([[1.0], [-0.5], [0.3]])
QDD = np.array([[0.2], [0.1], [-1.0]])
W = np.array([0.0, 0.0, 0.1, 1.0, -2.0, 0.0])  # one wrench, broadcast (the empty-batch check)
BAD_WRENCHES = ("x", {"no_such_site": np.zeros(6)}, {"coupler_point": np.full(6, np.nan)}, [np.zeros(6)])
BAD_WEIGHTS = ("x", np.array([-1.0]), np.array([0.0]), np.array([1.0, 1.0]), np.array([np.nan]))

SPECS = {
    P + "inverse_dynamics": Spec(
        args={
            "mech": MECH,
            "q": Q,
            "qd_act": QD,
            "qdd_act": QDD,
            "wrenches": {"coupler_point": W},
            "weights": np.array([1.0]),
            "gravity": True,
        },
        arrays={"q": 1, "qd_act": 1, "qdd_act": 1},
        masked=("q", "qd_act", "qdd_act"),
        mask="valid",
        params=("mech",),
        options={"gravity": BAD_BOOL, "wrenches": BAD_WRENCHES, "weights": BAD_WEIGHTS},
    ),
    P + "statics": Spec(
        args={"mech": MECH, "q": Q, "wrenches": {"coupler_point": W}, "weights": None, "gravity": True},
        arrays={"q": 1},
        masked=("q",),
        mask="valid",
        params=("mech",),
        options={"gravity": BAD_BOOL, "wrenches": BAD_WRENCHES, "weights": BAD_WEIGHTS},
    ),
    P + "site_wrench": Spec(
        args={"mech": MECH, "q": Q, "site": "coupler_point", "tau": QDD, "gravity": True},
        arrays={"q": 1, "tau": 1},
        masked=("q", "tau"),
        mask="valid",
        params=("mech",),
        options={"site": (None, 1, "no_such_site"), "gravity": BAD_BOOL},
    ),
    P + "forward_dynamics": Spec(
        args={"mech": MECH, "q": Q, "qd_act": QD, "tau": QDD, "wrenches": None, "gravity": True},
        arrays={"q": 1, "qd_act": 1, "tau": 1},
        masked=("q", "qd_act", "tau"),
        mask="valid",
        params=("mech",),
        options={"gravity": BAD_BOOL, "wrenches": BAD_WRENCHES},
    ),
    P + "energy": Spec(
        args={"mech": MECH, "q": Q, "qd": np.ones((3, 3))},
        arrays={"q": 1, "qd": 1},
        nan_rows=("q",),  # a failed FK sample chains: NaN energies at that sample
        params=("mech",),
    ),
    P + "simulate": Spec(
        args={
            "mech": MECH,
            "q0": Q[:2],
            "qd_act0": QD[:2],
            "t": np.array([0.0, 0.01]),
            "gravity": True,
            "tau": np.array([[0.1], [0.0]]),  # held actuator torques (a callable is the other form)
        },
        arrays={"q0": 1, "qd_act0": 1, "tau": 1},
        params=("mech",),
        options={
            "t": (None, "x", np.array([0.0]), np.array([0.1, 0.0]), np.array([0.0, np.nan])),
            "gravity": BAD_BOOL,
        },
    ),
    **exempt(
        "InverseDynamicsResult StaticsResult SiteWrenchResult ForwardDynamicsResult SimulationResult",
        RESULT_TYPE,
        P,
    ),
}
