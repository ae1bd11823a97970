"""SO(3), SE(3) and screw algebra, batched over leading dimensions.

Conventions (``docs/conventions.md``): twists ``[w; v]``, wrenches ``[m; f]``; ``T_AB`` maps points
in B to A so ``T_AC = T_AB @ T_BC``; SI units and radians.
"""

from ._se3 import (
    ad,
    adjoint,
    exp_se3,
    hat_se3,
    inverse_transform,
    lie_bracket,
    log_se3,
    reciprocal_product,
    screw_from_axis,
    screw_to_axis,
    transform,
    vee_se3,
    virtual_power,
    wrench_at,
)
from ._so3 import SMALL_ANGLE, exp_so3, hat, log_so3, rot_x, rot_y, rot_z, sincos, vee

__all__ = [
    "SMALL_ANGLE",
    "ad",
    "adjoint",
    "exp_se3",
    "exp_so3",
    "hat",
    "hat_se3",
    "inverse_transform",
    "lie_bracket",
    "log_se3",
    "log_so3",
    "reciprocal_product",
    "rot_x",
    "rot_y",
    "rot_z",
    "screw_from_axis",
    "screw_to_axis",
    "sincos",
    "transform",
    "vee",
    "vee_se3",
    "virtual_power",
    "wrench_at",
]
