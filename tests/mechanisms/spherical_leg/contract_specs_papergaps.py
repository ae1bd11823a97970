"""Bad-input specs of the spherical-leg names added by issues 14/15 (papergaps: branch tracking, bound).

Kept apart from ``mechanisms_spherical_leg.py`` (the loader reads every file here) so the two merge cleanly.
"""

import numpy as np
from contract_spec import CONSTANT, RESULT_TYPE, Spec

from robomech.mechanisms import spherical_leg as sl

P = "robomech.mechanisms.spherical_leg."
LEG = sl.SphericalLeg.paper()
_A = np.array([0.1, 0.12, 0.14, 0.16])
LENGTHS = sl.inverse_kinematics(LEG, _A, 0.2).lengths  # a 4-sample trajectory (4, 3)

SPECS = {
    P + "ACTUATION_SIGMA_MIN": CONSTANT,
    # issue 13: the base universal joints' spin, and the former model without it on request
    P + "CARDAN_LOCK_TOL": CONSTANT,
    P + "BranchTrack": RESULT_TYPE,
    P + "track_branches": Spec(
        args={"leg": LEG, "lengths": LENGTHS, "branch": 0},
        arrays={"lengths": 1},
        masked=("lengths",),
        mask="valid",
        params=("leg",),
        options={"branch": (2, -1, 0.5, None, "0", True)},
        wrong_shapes={"lengths": ((3,),)},
    ),
}
