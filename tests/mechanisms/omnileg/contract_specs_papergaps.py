"""Bad-input specs of the OmniLeg names added by issues 14/15 (papergaps: rates, workspace, conventions).

Kept apart from ``mechanisms_omnileg.py`` (the loader reads every file here) so the two merge cleanly.
"""

import numpy as np
from contract_spec import BAD_INT, BAD_NONNEGATIVE, CONSTANT, RESULT_TYPE, Exempt, Spec, exempt

from robomech.mechanisms import omnileg as ol

P = "robomech.mechanisms.omnileg."
LEG = ol.OmniLeg.paper()
Q = np.array([[0.1, 0.2, 0.5], [-0.2, 0.1, 0.7], [0.0, 0.0, 0.3]])
PD = np.array([[0.01, -0.02, 0.03], [0.0, 0.05, -0.01], [0.02, 0.02, 0.02]])
P_FOOT = ol.forward_kinematics(LEG, Q)

SPECS = {
    P + "FOOT_FORCE_CONVENTION": CONSTANT,
    P + "BodySet": Exempt(
        "read-only mapping built by OmniLeg.__post_init__ from a validated dict; users pass a plain dict"
    ),
    **exempt("JointRatesResult FootWorkspace SymmetryResult WorkspaceMap", RESULT_TYPE, P),
    P + "joint_rates": Spec(
        args={"leg": LEG, "q": Q, "foot_velocity": PD, "foot_acceleration": PD[::-1].copy(), "damping": 1e-3},
        arrays={"q": 1, "foot_velocity": 1, "foot_acceleration": 1},
        nan_rows=("q", "foot_velocity", "foot_acceleration"),
        params=("leg",),
        options={"damping": BAD_NONNEGATIVE},
    ),
    P + "workspace_map": Spec(args={"leg": LEG, "q": Q}, arrays={"q": 1}, nan_rows=("q",), params=("leg",)),
    P + "joint_grid": Spec(
        args={"leg": LEG, "n": 3}, params=("leg",), options={"n": (*BAD_INT, 1, 0, (2, 2), (3, 3, 1))}
    ),
    P + "singular_surface": Spec(
        args={"leg": LEG, "alpha": np.array([0.1, -0.2, 0.3]), "beta": np.array([0.0, 0.2, -0.4])},
        arrays={"alpha": 0, "beta": 0},
        params=("leg",),
        wrong_shapes={"alpha": ((4,),), "beta": ((2,),)},
    ),
    P + "foot_workspace": Spec(
        args={"leg": LEG, "nodes": 8}, params=("leg",), options={"nodes": (*BAD_INT, 1)}
    ),
    P + "workspace_symmetry": Spec(
        args={"leg": LEG, "p_foot": P_FOOT},
        arrays={"p_foot": 1},
        masked=("p_foot",),
        mask="reachable",
        params=("leg",),
    ),
}
