"""Every numerical tolerance and iteration limit of the multibody layer, with its reason.

One module, imported by the compile step, the compiled kernels and the analysis modules alike (it
imports nothing of the layer), so that a tolerance has one value and one justification.  The public
names (``CONVERGED_RTOL``, ``SINGULAR_COND``, ...) are re-exported where users find them.
"""

from __future__ import annotations

__all__ = [
    "ADMISSIBLE_RTOL",
    "ASSEMBLED_RTOL",
    "CLOSURE_RTOL",
    "CONVERGED_RTOL",
    "GRAM_COND_MAX",
    "GRAM_REFINE2_COND",
    "GRAM_REFINE_COND",
    "MAX_ITER",
    "MAX_STEP",
    "MIN_NORM",
    "MOBILITY_RTOL",
    "MU_MAX",
    "MU_MIN",
    "MU_START",
    "NEIGHBOUR_STEP",
    "PASSIVE_RANK_RTOL",
    "QUAT_MIN_NORM",
    "RANK_RTOL",
    "RATE_FLOOR",
    "ROTATION_TOL",
    "SINGULAR_COND",
    "STOP_RTOL",
]

# ----------------------------------------------------------------------------- the description
# Quaternions and axes given by the user are normalised; a norm below this is not a direction.
MIN_NORM = 1e-12
# A reference configuration "is assembled" (MuJoCo's qpos0 semantics hold for an exported closure)
# when the two anchors of a closure coincide to this distance relative to the mechanism size:
# a few hundred ulps of the coordinates.
ASSEMBLED_RTOL = 1e-10
# A rotation matrix must satisfy R^T R = I and det R = +1 to this tolerance: composed transforms are
# orthonormal to ~1e-15, a matrix typed with 7 significant digits to ~1e-7; a wrong frame (a
# non-orthogonal or reflected matrix, e.g. a swapped axis) is off by O(1).
ROTATION_TOL = 1e-6
# Ball and free quaternions below this norm cannot be normalised; the kinematics uses identity there
# (only reachable from user input, which the public boundary rejects as non-finite or zero).
QUAT_MIN_NORM = 1e-300

# ----------------------------------------------------------------------------- assembly
# A configuration is assembled when every closure row is below CONVERGED_RTOL * L (L the
# characteristic length): 1e-10 m for a 1 m mechanism, far below any manufacturing tolerance and
# well above the ~1e-15 L where Newton's quadratic convergence stops (rounding).
CONVERGED_RTOL = 1e-10
# A sample stops iterating once its residual is below STOP_RTOL * L: a few ulps of the coordinates.
STOP_RTOL = 1e-14
# Levenberg–Marquardt damping, relative to the mean diagonal of K^T K.  Start nearly at Gauss–Newton
# (quadratic convergence near a solution); x10 on a rejected step, /10 on an accepted one; a sample
# whose damping exceeds MU_MAX takes steps of relative size < 1e-10: it has stalled and stops.
MU_START = 1e-8
MU_MIN = 1e-14
MU_MAX = 1e10
# Largest step per iteration, in radians (translations divided by L): Gauss–Newton far from a
# solution can take steps of many radians and land on another assembly branch; capping the step keeps
# the iteration on the branch connected to the guess (0.5 rad: the closure equations are nearly
# linear over such a step) at the cost of a few more iterations for large moves.  Only coordinates
# that move a closure point or the IK site are capped.
MAX_STEP = 0.5
# Iterations per continuation stage: from the reference configuration Newton takes 4-8 iterations on
# the gallery; 60 leaves room for the damped steps far from a solution before a sample is given up.
MAX_ITER = 60

# ----------------------------------------------------------------------------- ranks and conditioning
# Singular values of K_p below PASSIVE_RANK_RTOL * sigma_max are zero in the pseudo-inverse: K_p is
# built from unit screws times lengths of order L, so rounding leaves ~1e-15 relative; a genuine
# (non-singular) passive direction of a well-posed mechanism is far above 1e-10.
PASSIVE_RANK_RTOL = 1e-10
# Singular values of the unit-scaled K below MOBILITY_RTOL * sigma_max count as zero: entries are
# unit screws times lengths of order L, rounding leaves ~1e-15 relative, and a configuration
# 1e-4 rad from a singularity (NEIGHBOUR_STEP) still has the vanishing value ~1e-4 >> 1e-9.
MOBILITY_RTOL = 1e-9
# The "locally constant rank" test re-assembles the mechanism this far (rad, or L for translations)
# along each admissible direction and compares the ranks there.
NEIGHBOUR_STEP = 1e-4

# ----------------------------------------------------------------------------- dynamics
# A configuration is flagged singular when the passive block K_p of the constraint Jacobian has a
# condition number above SINGULAR_COND (or lost rank against the reference configuration): actuator
# forces grow like cond, and the closure is only solved to CONVERGED_RTOL = 1e-10 relative, so beyond
# 1e6 the forces would carry relative errors of order 1e-4 from the geometry alone — and they are
# physically unbounded as cond -> inf.  Such samples get valid = False and NaN forces.
SINGULAR_COND = 1e6
# The prescribed motion must be admissible: |K qd| and |K qdd + Kdot qd| below ADMISSIBLE_RTOL times
# their scale (L |qd|, L (|qdd| + |qd|^2)).  Rounding leaves ~1e-15; an inconsistent rate of a
# redundantly actuated mechanism (or a rank drop) gives O(1).
ADMISSIBLE_RTOL = 1e-8
# ... and below RATE_FLOOR (1/s, 1/s^2) of motion the scale is RATE_FLOOR: at rest the test is absolute
# (1e-8 L per s^2), not relative to zero.
RATE_FLOOR = 1.0
# Rank decisions on K G (redundant actuation) and on the forward-dynamics matrices: singular values
# below this fraction of the largest are zero (the same reasoning as PASSIVE_RANK_RTOL).
RANK_RTOL = PASSIVE_RANK_RTOL
# Below this 1-norm condition estimate of K_p the Gram-matrix inverse (with refinement) is used; above it
# the sample is recomputed with the SVD pseudo-inverse (exact rank decision).  The Gram matrix squares
# the condition number: its inverse carries ~cond^2 eps relative error, and each refinement step
# (x += P0 (b - K_p x)) multiplies the error by ~cond^2 eps again.  SINGULAR_COND: beyond it the sample
# is invalid anyway, and the estimate bounds the 2-norm condition number from above (within sqrt(rank)),
# so a sample judged by the estimate is never wrongly valid.
GRAM_COND_MAX = SINGULAR_COND
# Refinement steps: one above GRAM_REFINE_COND (below it cond^2 eps < 1e-12), two above
# GRAM_REFINE2_COND (at cond 1e6: 1e-4 -> 1e-8 -> 1e-12, below the inherent cond eps ~ 1e-10).
GRAM_REFINE_COND = 1e2
GRAM_REFINE2_COND = 1e4
# A configuration given to a dynamics function must satisfy the closures: its largest closure row at most
# CLOSURE_RTOL * L.  100 times the assembly's CONVERGED_RTOL, so that every configuration that
# forward_kinematics, inverse_kinematics or simulate report converged passes, while one off the closure
# manifold (a passive joint moved by hand, a q typed with a few digits) gives forces of no meaning and
# is flagged: the forces' relative error grows like the residual over L.
CLOSURE_RTOL = 1e-8
