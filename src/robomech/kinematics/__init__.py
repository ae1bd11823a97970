"""Serial-chain kinematics: product of exponentials, Jacobians, second-order influence coefficients."""

from ._poe import hessian_body, hessian_space, jacobian_body, jacobian_derivative, jacobian_space, poe_fk

__all__ = [
    "hessian_body",
    "hessian_space",
    "jacobian_body",
    "jacobian_derivative",
    "jacobian_space",
    "poe_fk",
]
