"""The spherical parallel leg described generically (``robomech.multibody``), from its parameters: chains,
joints and closures in docs/mechanisms/spherical_leg.md, "Generic description"."""

from __future__ import annotations

import numpy as np

from robomech.multibody import Builder, Inertial, Mechanism
from robomech.multibody._model import _quat_from_matrix

from ._params import SphericalLeg

__all__ = ["to_multibody"]


def to_multibody(leg: SphericalLeg, actuate: str = "legs") -> Mechanism:
    """The generic description of ``leg``; q_act = the leg extensions, or (alpha, beta).

    ``actuate="legs"``: the robot, three legs on a 2-DOF platform (redundantly actuated);
    ``"platform"``: alpha, beta as inputs (then ``G``'s leg rows are the analytic J).
    """
    if not isinstance(leg, SphericalLeg):
        raise ValueError(f"Expected leg to be a SphericalLeg, got {type(leg).__name__}.")
    if actuate not in ("legs", "platform"):
        raise ValueError(f"Expected actuate to be 'legs' or 'platform', got {actuate!r}.")
    b = Builder("spherical_leg", gravity=leg.gravity)
    b.body("cross", joints=[b.hinge("alpha", axis=(1, 0, 0))])
    pi_ = leg.platform_inertia
    b.body(
        "platform",
        "cross",
        joints=[b.hinge("beta", axis=(0, 1, 0))],
        inertial=Inertial(leg.platform_mass, (0.0, 0.0, leg.h), (1, 0, 0, 0), tuple(np.diag(pi_))),
    )
    b.site("platform", "platform", pos=(0.0, 0.0, leg.h))
    A, B = leg.base_points, leg.platform_points_home
    spin = leg.spin_ratio
    for i in range(3):
        v = B[i] - A[i]
        l0 = float(np.linalg.norm(v))
        x = v / l0
        y = leg.cardan_axes[i]  # the U joint's base-fixed axis (horizontal, across the leg at home)
        R = np.column_stack([x, y, np.cross(x, y)])  # x along the leg; U axes y, z across it
        k = i + 1
        lo, up = leg.lower[i], leg.upper[i]
        b.body(
            f"cardan{k}",
            pos=A[i],
            quat=_quat_from_matrix(R),
            joints=[b.hinge(f"u{k}a", axis=(0, 1, 0)), b.hinge(f"u{k}b", axis=(0, 0, 1))],
        )
        lower = Inertial(
            lo.mass,
            (lo.length / 2, 0, 0),
            (1, 0, 0, 0),
            (lo.axial_inertia, lo.transverse_inertia, lo.transverse_inertia),
        )
        if spin[i] != 0.0:
            # legs 1, 3 (RUHU): the lead screw spins about the leg axis relative to the non-spinning sleeve
            b.body(f"screw{k}", f"cardan{k}", joints=[b.hinge(f"spin{k}", axis=(1, 0, 0))], inertial=lower)
        else:
            b.body(f"lower{k}", f"cardan{k}", inertial=lower)
        upper = Inertial(
            up.mass,
            (l0 - up.length / 2, 0, 0),
            (1, 0, 0, 0),
            (up.axial_inertia, up.transverse_inertia, up.transverse_inertia),
        )
        b.body(f"upper{k}", f"cardan{k}", joints=[b.slide(f"l{k}", axis=(1, 0, 0))], inertial=upper)
        b.connect(f"B{k}", f"upper{k}", "platform", anchor1=(l0, 0.0, 0.0), anchor2=B[i])
        if spin[i] != 0.0:
            b.couple(f"screw{k}", f"spin{k}", f"l{k}", (0.0, float(spin[i])))
    if actuate == "legs":
        b.actuate("l1", "l2", "l3")
    else:
        b.actuate("alpha", "beta")
    return b.build()
