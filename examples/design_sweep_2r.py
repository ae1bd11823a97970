"""
A design sweep
==============

The link-length ratio of a planar 2R arm that gives an isotropic tip Jacobian.

For every ratio l2/l1 on a grid and every elbow angle, the tip Jacobian comes from the product of
exponentials (``kinematics.jacobian_space``: space twists ``[w; v]``, turned into the tip velocity
``v + w x p``); ``analysis.workspace.condition_number`` maps its conditioning.  The best ratio is
compared with the known optimum: the 2R arm has an isotropic point (condition number 1) only for
l2/l1 = 1/sqrt(2), at an elbow angle of 135 deg (Salisbury and Craig, Int. J. Robotics Research
1(1), 1982).  The whole sweep is one batched call: ratios x elbow angles.
"""

import numpy as np

from robomech.analysis import workspace
from robomech.kinematics import jacobian_space, poe_fk
from robomech.spatial import screw_from_axis

L1 = 1.0  # m
RATIO_STEP = 0.005
ELBOW_STEP = np.deg2rad(0.5)
ratios = np.arange(0.30, 1.50 + RATIO_STEP / 2, RATIO_STEP)  # l2 / l1
elbow = np.arange(ELBOW_STEP, np.pi, ELBOW_STEP)  # rad; the shoulder angle does not change the conditioning
# the grid resolves the optimum to one step of each axis
RATIO_ATOL, ELBOW_ATOL = RATIO_STEP, ELBOW_STEP

z = np.array([0.0, 0.0, 1.0])
r, th = np.meshgrid(ratios, elbow, indexing="ij")  # (n_ratio, n_elbow)
# joint screws (2, 6): hinges at the origin and at x = l1; only the home pose of the tip depends on l2,
# so M is a batch (n_ratio, 1, 4, 4) that broadcasts against q (n_ratio, n_elbow, 2)
screws = screw_from_axis(np.stack([z, z]), np.array([[0.0, 0.0, 0.0], [L1, 0.0, 0.0]]))
M = np.tile(np.eye(4), (len(ratios), 1, 1, 1))
M[..., 0, 3] = (L1 + L1 * ratios)[:, None]  # tip at x = l1 + l2 when q = 0
q = np.stack([np.zeros_like(th), th], axis=-1)  # (n_ratio, n_elbow, 2)

T = poe_fk(M, screws, q)  # (n_ratio, n_elbow, 4, 4)
J = jacobian_space(screws, q)  # (n_ratio, n_elbow, 6, 2)
p = T[..., :3, 3]
v_tip = J[..., 3:, :] + np.cross(J[..., :3, :], p[..., :, None], axis=-2)  # tip velocity per joint rate
cond = workspace.condition_number(v_tip[..., :2, :])  # planar: x, y rows

best = np.unravel_index(np.argmin(cond), cond.shape)
best_ratio, best_elbow = ratios[best[0]], elbow[best[1]]
print(f"best ratio l2/l1 = {best_ratio:.3f} (1/sqrt(2) = {1 / np.sqrt(2):.3f})")
print(f"at elbow angle {np.rad2deg(best_elbow):.1f} deg, condition number {cond[best]:.4f}")
for k in range(0, len(ratios), 40):
    print(f"  l2/l1 = {ratios[k]:.2f}: best condition number {cond[k].min():.3f}")
assert abs(best_ratio - 1 / np.sqrt(2)) <= RATIO_ATOL
assert abs(best_elbow - np.deg2rad(135.0)) <= ELBOW_ATOL

# The sweep as a map: log10 of the condition number over ratio and elbow angle, the optimum marked.
import matplotlib.pyplot as plt  # noqa: E402

fig, ax = plt.subplots(figsize=(6, 4))
im = ax.pcolormesh(np.rad2deg(elbow), ratios, np.log10(cond), shading="auto", cmap="viridis", vmax=2)
fig.colorbar(im, ax=ax, label="log10 condition number of the tip Jacobian")
ax.plot(np.rad2deg(best_elbow), best_ratio, "r+", ms=14, mew=2, label="isotropic optimum")
ax.set_xlabel("elbow angle (deg)")
ax.set_ylabel("link ratio l2/l1")
ax.legend(loc="upper left")
print("OK")
