"""Bad-input specs of robomech.testing (finite-difference references)."""

import numpy as np
from contract_spec import BAD_POSITIVE, Spec

from robomech.spatial import exp_se3

P = "robomech.testing."
X = np.array([[0.1, 0.2], [0.3, -0.4]])


def _f(x):
    return np.stack([np.sin(x[..., 0]) * x[..., 1], x[..., 0] ** 2], axis=-1)


def _fk(q):
    return exp_se3(np.concatenate([q, q[..., :1], np.zeros((*q.shape[:-1], 3))], axis=-1))


SPECS = {
    P + "numerical_jacobian": Spec(
        args={"f": _f, "x": X, "h": 1e-6},
        arrays={"x": 1},
        wrong_shapes={"x": ()},
        params=("f",),
        options={"h": BAD_POSITIVE},
    ),
    P + "numerical_hessian": Spec(
        args={"jac": _f, "x": X, "h": 1e-6},
        arrays={"x": 1},
        wrong_shapes={"x": ()},
        params=("jac",),
        options={"h": BAD_POSITIVE},
    ),
    P + "numerical_space_jacobian": Spec(
        args={"fk": _fk, "q": X, "h": 1e-6},
        arrays={"q": 1},
        wrong_shapes={"q": ()},
        params=("fk",),
        options={"h": BAD_POSITIVE},
    ),
}
