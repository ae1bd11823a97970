"""The RRR-RR vectored thruster described generically (``robomech.multibody``), from its parameters: bodies,
hinges and the cut joint in docs/mechanisms/vectored_thrust.md, "Generic description"."""

from __future__ import annotations

import numpy as np

from robomech.multibody import Builder, Mechanism

from ._params import VectoredThruster

__all__ = ["to_multibody"]


def to_multibody(th: VectoredThruster) -> Mechanism:
    """The generic description of ``th`` (a :class:`VectoredThruster`); q_act = (q1, q2)."""
    if not isinstance(th, VectoredThruster):
        raise ValueError(f"Expected th to be a VectoredThruster, got {type(th).__name__}.")
    a = th.arc_angle
    s12 = np.array([np.cos(a), 0.0, -np.sin(a)])  # paper 5, eq. (7) at q1 = 0
    s22 = np.array([-1.0, 0.0, 0.0])  # eq. (5) at q2 = 0
    s13 = np.cross(s22, s12)
    s13 /= np.linalg.norm(s13)  # eq. (8)
    b = Builder("vectored_thrust", gravity=(0.0, 0.0, 0.0))
    b.body("rr_arc", joints=[b.hinge("q2", axis=(0, 1, 0))])
    b.body("platform", "rr_arc", joints=[b.hinge("theta", axis=s22)])
    b.body("rrr_arc1", joints=[b.hinge("q1", axis=(1, 0, 0))])
    b.body("rrr_arc2", "rrr_arc1", joints=[b.hinge("rho2", axis=s12)])
    b.revolute("rho3", "rrr_arc2", "platform", anchor1=(0.0, 0.0, 0.0), axis=s13)
    b.site("propeller", "platform", pos=(0.0, 0.0, th.propeller_arm))
    # arc ends, for a drawing and a visible MJCF export (they change no kinematics)
    b.site("rr_arc_end", "rr_arc", pos=th.rr_arc_radius * -s22)
    b.site("rrr_arc1_end", "rrr_arc1", pos=th.rrr_arc1_radius * s12)
    b.site("rrr_arc2_end", "rrr_arc2", pos=th.rrr_arc2_radius * -s13)
    b.actuate("q1", "q2")
    return b.build()
