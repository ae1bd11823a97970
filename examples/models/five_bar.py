"""A user's planar five-bar (RRRRR), described with the multibody Builder, for ``robomech sweep``.

``build(L1, L2, B)``: two proximal links of length ``L1`` hinged on the base at ``(-B/2, 0)`` and
``(B/2, 0)`` (the actuated hinges), two distal links of length ``L2`` joined at the tip, where the
site ``tip`` sits; all lengths in metres, motion in the world x-y plane.  The reference configuration
puts the tip on the symmetry axis with the elbows out (each leg's elbow at 90 degrees)::

    robomech sweep --model examples/models/five_bar.py:build --site tip \\
        --var L1=0.1:0.3 --var L2=0.1:0.3 --var B=0.05:0.2 \\
        --task-box -0.5:0.5,-0.5:0.5 --task-grid 32 --metric workspace_measure --metric dexterity_min \\
        --designs 64 --out five_bar.zarr
"""

import numpy as np

from robomech.multibody import Builder


def _quat_z(angle: float) -> tuple[float, float, float, float]:
    return (float(np.cos(angle / 2)), 0.0, 0.0, float(np.sin(angle / 2)))


def build(L1: float = 0.2, L2: float = 0.2, B: float = 0.1):
    d = np.hypot(L1, L2)  # base-to-tip distance with the elbow at 90 degrees
    if not d > B / 2:
        raise ValueError(f"Expected L1, L2 long enough to reach across B = {B}, got {L1}, {L2}.")
    tip = np.array([0.0, np.sqrt(d**2 - (B / 2) ** 2), 0.0])
    b = Builder("five_bar", gravity=(0.0, 0.0, 0.0))
    for i, (side, s) in enumerate((("left", -1.0), ("right", 1.0))):
        A = np.array([s * B / 2, 0.0, 0.0])
        e = (tip - A) / d
        n = s * np.array([e[1], -e[0], 0.0])  # elbow outwards, away from the symmetry axis
        x = L1**2 / d  # elbow B: |B - A| = L1, |tip - B| = L2, right angle at B
        elbow = A + x * e + np.sqrt(L1**2 - x**2) * n
        phi = float(np.arctan2(*(elbow - A)[1::-1]))
        psi = float(np.arctan2(*(tip - elbow)[1::-1]))
        b.body(f"proximal_{side}", pos=A, quat=_quat_z(phi), joints=[b.hinge(f"base_{side}", ref=phi)])
        b.body(
            f"distal_{side}",
            f"proximal_{side}",
            pos=(L1, 0, 0),
            quat=_quat_z(psi - phi),
            joints=[b.hinge(f"elbow_{side}", ref=psi - phi)],
        )
        if i == 0:
            b.site("tip", "distal_left", pos=(L2, 0, 0))
    b.revolute(
        "tip_joint", "distal_left", "distal_right", anchor1=(L2, 0, 0), anchor2=(L2, 0, 0), axis=(0, 0, 1)
    )
    b.actuate("base_left", "base_right")
    return b.build()
