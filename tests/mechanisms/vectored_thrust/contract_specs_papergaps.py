"""Bad-input specs of the vectored-thruster names added by issue 15 (papergaps: inverse rates, statics).

Kept apart from ``mechanisms_vectored_thrust.py`` (the loader reads every file here) so the two merge
cleanly.
"""

import numpy as np
from contract_spec import BAD_NONNEGATIVE, CONSTANT, RESULT_TYPE, Spec, exempt

from robomech.mechanisms import vectored_thrust as vt

P = "robomech.mechanisms.vectored_thrust."
TH = vt.VectoredThruster.paper()
Q = np.array([[0.1, 0.2], [-0.3, 0.1], [0.0, -0.2]])
W = np.array([[0.1, 0.2, 0.0], [0.0, -0.3, 0.1], [0.2, 0.0, 0.1]])

SPECS = {
    P + "INPUT_GAIN_MAX": CONSTANT,
    P + "RATE_RESIDUAL_ATOL": CONSTANT,
    P + "RATE_RESIDUAL_RTOL": CONSTANT,
    **exempt("InverseRatesResult StaticsResult", RESULT_TYPE, P),
    P + "inverse_rates": Spec(
        args={"th": TH, "q": Q, "omega": W, "omega_dot": W[::-1].copy(), "damping": 0.01},
        arrays={"q": 1, "omega": 1, "omega_dot": 1},
        nan_rows=("q", "omega", "omega_dot"),
        params=("th",),
        options={"damping": BAD_NONNEGATIVE},
    ),
    P + "static_torques": Spec(
        args={"th": TH, "q": Q, "wrench": np.concatenate([W, W], -1)},
        arrays={"q": 1, "wrench": 1},
        nan_rows=("q",),
        params=("th",),
    ),
}
