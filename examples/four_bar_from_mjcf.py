"""
Model a mechanism from MJCF
===========================

The planar four-bar shipped with robomech.

Loads the MJCF file (compiled by MuJoCo's own ``MjSpec``), assembles the loop for a sweep of crank
angles, and checks the rocker angle against the closed-form circle intersection (an independent
formulation: circles about the crank pin B and the rocker pivot D meet at the coupler pin C), and
the transmission ratio d(theta4)/d(theta2) of the influence coefficients against a central
difference of that closed form.
"""

import numpy as np

from robomech import multibody as mb

# Geometry of four_bar.xml (m): crank O->B 0.3, coupler B->C |(0.9, 0.5)|, rocker D->C 0.8, ground O->D 0.9.
CRANK, ROCKER = 0.3, 0.8
COUPLER = float(np.hypot(0.9, 0.5))
D = np.array([0.9, 0.0])
# FK solves the closure to 1e-10 of the mechanism size (CONVERGED_RTOL); the closed form is exact.
ANGLE_ATOL = 1e-8  # rad
# Central difference with step 1e-5 rad: truncation ~1e-10, rounding ~1e-11.
RATIO_ATOL = 1e-8


def rocker_angle(theta2: np.ndarray) -> np.ndarray:
    """theta4 from theta2 by intersecting two circles (the branch of the reference pose)."""
    # the crank starts along +y (euler 90 deg): B = CRANK (cos, sin)(pi/2 + theta2)
    B = CRANK * np.stack([np.cos(np.pi / 2 + theta2), np.sin(np.pi / 2 + theta2)], axis=-1)
    BD = D - B
    d = np.linalg.norm(BD, axis=-1)
    a = (COUPLER**2 - ROCKER**2 + d**2) / (2 * d)  # from B to the chord through both intersections
    h = np.sqrt(COUPLER**2 - a**2)
    perp = np.stack([-BD[..., 1], BD[..., 0]], axis=-1) / d[..., None]
    C = B + a[..., None] * BD / d[..., None] + h[..., None] * perp  # C = (0.9, 0.8) at theta2 = 0
    return np.arctan2(C[..., 1] - D[1], C[..., 0] - D[0]) - np.pi / 2  # the rocker starts along +y


mech = mb.from_mjcf(mb.gallery.path("four_bar"))
print("actuated:", mech.actuated, " nq =", mech.nq)

theta2 = np.linspace(-0.6, 0.6, 7)  # crank angles from the reference pose (rad)
fk = mb.forward_kinematics(mech, theta2[:, None])
assert fk.converged.all()
err = np.max(np.abs(fk.q[:, 2] - rocker_angle(theta2)))
print(f"rocker angle vs closed form: max error {err:.1e} rad")
assert err < ANGLE_ATOL

m = mb.mobility(mech)
print(f"mobility: dof {m.dof}, Gruebler-Kutzbach {m.gruebler_kutzbach}")

G = mb.influence(mech, fk.q).G[:, 2, 0]  # d(theta4)/d(theta2): rocker rate per unit crank rate
step = 1e-5
G_fd = (rocker_angle(theta2 + step) - rocker_angle(theta2 - step)) / (2 * step)
assert np.max(np.abs(G - G_fd)) < RATIO_ATOL
for t2, g in zip(theta2, G, strict=True):
    print(f"  theta2 = {t2:+.2f} rad   d(theta4)/d(theta2) = {g:+.4f}")
print(f"transmission ratio vs closed form: max error {np.max(np.abs(G - G_fd)):.1e}")

# The linkage at the extreme crank angles, drawn by robomech (matplotlib; the docs gallery shows it).
import matplotlib.pyplot as plt  # noqa: E402

fig = plt.figure(figsize=(5, 4))
ax = fig.add_subplot(projection="3d")
for k, color in ((0, "C0"), (len(theta2) - 1, "C1")):
    mb.draw(mech, fk.q[k], ax=ax, color=color, title="four-bar at crank angles -0.6 and +0.6 rad")
ax.view_init(elev=90, azim=-90)  # the linkage moves in the x-y plane
print("OK")
