"""Bad-input specs of robomech.analysis (lstsq, mobility, workspace)."""

import numpy as np
from contract_spec import BAD_BOOL, BAD_INT, BAD_POSITIVE, BAD_REAL, CONSTANT, RESULT_TYPE, Spec

from robomech.spatial import screw_from_axis

P = "robomech.analysis."
rng = np.random.default_rng(0)
A = rng.normal(size=(3, 5, 3))
B = rng.normal(size=(3, 5))
J = rng.normal(size=(3, 4, 3))
# 3-RPS parallel platform: three chains R (tangent), P (radial-vertical), S (three axes at the tip)
_CHAINS = []
for k in range(3):
    a = 2 * np.pi * k / 3
    base = np.array([np.cos(a), np.sin(a), 0.0])
    tip = np.array([0.5 * np.cos(a), 0.5 * np.sin(a), 1.0])
    tangent = np.array([-np.sin(a), np.cos(a), 0.0])
    leg = (tip - base) / np.linalg.norm(tip - base)
    S = [screw_from_axis(tangent, base), np.concatenate([np.zeros(3), leg])]
    S += [screw_from_axis(ax, tip) for ax in np.eye(3)]
    _CHAINS.append(np.array(S))
BAD_TOL = (*BAD_REAL, 0.0, -1e-9, 1.0)

SPECS = {
    P + "lstsq.RANK_RTOL_FACTOR": CONSTANT,
    P + "lstsq.LstsqResult": RESULT_TYPE,
    P + "lstsq.solve": Spec(
        args={"A": A, "b": B, "exact_cond": False, "weights": np.tile(np.linspace(0.5, 2.0, 5), (3, 1))},
        arrays={"A": 2, "b": 1, "weights": 1},
        masked=("A", "b"),
        mask="ok",
        wrong_shapes={"A": ((3, 2, 3),)},  # fewer rows than columns
        options={"exact_cond": BAD_BOOL},
    ),
    P + "lstsq.solve_normal_equations": Spec(
        args={"A": A, "b": B},
        arrays={"A": 2, "b": 1},
        masked=("A", "b"),
        mask="ok",
        wrong_shapes={"A": ((3, 2, 3),)},
    ),
    P + "lstsq.rank_cond_limit": Spec(
        args={"m": 30, "n": 11}, options={"m": (*BAD_INT, 0), "n": (*BAD_INT, 0)}
    ),
    P + "mobility.RANK_RTOL": CONSTANT,
    P + "mobility.UNIT_SCREW_ATOL": CONSTANT,
    P + "mobility.ChainScrews": RESULT_TYPE,
    P + "mobility.MobilityResult": RESULT_TYPE,
    P + "mobility.analyze": Spec(
        args={"chains": _CHAINS, "length_scale": 1.0, "tol": 1e-9},
        options={
            "chains": (
                None,
                "abc",
                [],
                np.stack(_CHAINS),
                [_CHAINS[0].T],
                [_CHAINS[0][:, :5]],
                [np.nan * _CHAINS[0]],
            ),
            "length_scale": BAD_POSITIVE,
            "tol": BAD_TOL,
        },
    ),
    P + "mobility.constraint_wrenches": Spec(
        args={"twists": _CHAINS[0][:3], "tol": 1e-9},
        arrays={"twists": 2},
        wrong_shapes={"twists": ((2, 3, 6),)},
        options={"tol": BAD_TOL},
    ),
    P + "mobility.reciprocal_basis": Spec(
        args={"screws": _CHAINS[0][:3], "tol": 1e-9},
        arrays={"screws": 2},
        wrong_shapes={"screws": ((2, 3, 6),)},
        options={"tol": BAD_TOL},
    ),
    P + "workspace.SingularityMap": RESULT_TYPE,
    P + "workspace.condition_number": Spec(args={"J": J}, arrays={"J": 2}, wrong_shapes={"J": ((3,),)}),
    P + "workspace.singularity_map": Spec(
        args={"J": J, "rtol": 1e-8},
        arrays={"J": 2},
        masked=("J",),
        mask=lambda r: ~r.singular,
        wrong_shapes={"J": ((3,),)},
        options={"rtol": (*BAD_REAL, 0.0, 2.0)},
        finite_result=True,
    ),
    P + "workspace.grid": Spec(
        args={"ranges": [(0.0, 1.0), (-1.0, 1.0)], "n": 3},
        arrays={"ranges": 1},
        wrong_shapes={"ranges": ((2, 3),)},
        options={"n": (*BAD_INT, 1, [3]), "ranges": ([(1.0, 0.0)], [])},
        empty_batch=False,  # ranges (d, 2) lists coordinates, not samples
    ),
}
