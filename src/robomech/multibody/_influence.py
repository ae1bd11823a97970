"""First- and second-order influence coefficients of any closed chain (exact, batched).

At an assembled ``q`` the admissible velocities satisfy ``K qd = 0``.  Splitting the velocity
coordinates into actuated (a) and passive (p), ``qd_p = -K_p^+ K_a qd_a``, so

    G = ∂qd/∂qd_a = [I; -K_p^+ K_a]                       (nv, n_act), rows in qvel order,

the minimum-norm choice where the passive coordinates include idle motions (a leg spinning about its
own axis), which move no site and so leave every site Jacobian unique.  Differentiating ``K G = 0``
along the motion ``qd = G e_k``:

    ∂G/∂q_a,k = [0; -K_p^+ (dK/dt|_{qd = G e_k}) G]        (the papers' second-order coefficients),

and for a site with ``[ω; ṗ] = J_f qd``: ``J = J_f G`` and ``∂J/∂q_a,k = (dJ_f/dt) G + J_f ∂G/∂q_a,k``.
Nothing here is a finite difference; the tests compare with ``robomech.testing``.  ``G``, ``∂G/∂q_a``
and the site Hessian are computed per sample by the compiled kernels (``_compiled.influence_block``,
the same ``G`` as the site Jacobian's and the dynamics'); their numpy formulation is the tests'
reference (tests/multibody/_reference.py).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from robomech._batching import failed_rows, on_rows
from robomech._validation import as_array, broadcast_batch, check_bool

from ._assembly import check_mechanism, check_q
from ._compile import compile_model
from ._model import Mechanism
from ._options import PASSIVE_RANK_RTOL

__all__ = [
    "PASSIVE_RANK_RTOL",
    "Influence",
    "constraint_jacobian",
    "constraint_jacobian_rate",
    "constraint_residual",
    "influence",
    "site_hessian",
    "site_jacobian",
    "site_pose",
]


@dataclass(frozen=True)
class Influence:
    """``G (..., nv, n_act)`` and ``dG (..., nv, n_act, n_act)`` with ``dG[..., i, j, k] = ∂G_ij/∂q_act,k``.

    The result of :func:`influence`; ``...`` is the batch shape of ``q``.

    Attributes
    ----------
    G : ndarray, shape (..., nv, n_act)
        First-order influence coefficients ``∂qd/∂qd_act`` (rows in MuJoCo ``qvel`` order, columns in
        actuator order; the actuated rows are the identity).
    dG : ndarray, shape (..., nv, n_act, n_act), or None
        Second-order coefficients ``∂G/∂q_act``; None when ``second_order=False``.
    passive_rank : ndarray of int, shape (...)
        Rank of the passive constraint block ``K_p`` (``passive_rank < n_passive``: idle or
        undetermined passive motion).
    n_passive : int
        Number of passive velocity coordinates (columns of ``K_p``).
    consistency : ndarray, shape (...)
        ``max |K G| / L``: zero where every input rate is admissible, > 0 with redundant actuation
        (only admissible ``qd_act`` then have a meaning).
    sigma_min : ndarray, shape (...)
        Smallest non-zero singular value of ``K_p`` (m); the characteristic length where ``K_p`` is
        empty (an open chain or tree: nothing can lose rank).
    cond : ndarray, shape (...)
        Condition number of ``K_p`` (1 where it is empty).
    """

    G: np.ndarray
    dG: np.ndarray | None
    passive_rank: np.ndarray
    n_passive: int
    consistency: np.ndarray
    sigma_min: np.ndarray
    cond: np.ndarray


def _site_index(mech: Mechanism, site: object) -> int:
    if not isinstance(site, str):
        raise ValueError(f"Expected site to be a site name (str), got {type(site).__name__}.")
    return mech.tree.site_index(site)


def _flat(mech: Mechanism, q: object) -> tuple[np.ndarray, tuple[int, ...]]:
    q = check_q(mech, q, nan_rows=True)  # a NaN sample (a failed FK sample) gives NaN out: on_rows
    return q.reshape(-1, mech.nq), q.shape[:-1]


def influence(mech: Mechanism, q: object, *, second_order: bool = True) -> Influence:
    """``G = ∂q/∂q_act`` (velocity coordinates) and ``∂G/∂q_act`` at assembled configurations ``q (..., nq)``.

    ``Ġ = einsum("...ijk,...k->...ij", dG, qd_act)`` and ``qdd = G qdd_act + einsum("...ijk,...j,...k->...i",
    dG, qd_act, qd_act)``.  ``G = [I; -K_p^+ K_a]`` (rows in ``qvel`` order) is the minimum-norm choice
    where the passive coordinates include idle motions (module docstring); nothing is a finite difference.

    Parameters
    ----------
    mech : Mechanism
        The described mechanism.
    q : array_like, shape (..., nq)
        Assembled configurations (MuJoCo ``qpos``; e.g. ``forward_kinematics(mech, q_act).q``).  Not
        checked for closure: at an unassembled ``q`` the coefficients have no meaning.
    second_order : bool, optional
        Also compute ``dG`` (default True); False leaves ``Influence.dG`` None and is cheaper.

    Returns
    -------
    Influence
        ``G (..., nv, n_act)`` (rad/rad, m/rad, ... per velocity coordinate and unit input rate),
        ``dG (..., nv, n_act, n_act)`` or None, and per sample ``passive_rank``, ``consistency``,
        ``sigma_min`` (m), ``cond``; ``n_passive`` an int.

    Raises
    ------
    ValueError
        If ``mech`` is not a Mechanism, ``q`` is not finite real of shape ``(..., nq)``, or ``second_order``
        is not a bool.

    Examples
    --------
    >>> import numpy as np
    >>> from robomech import multibody as mb
    >>> mech = mb.gallery.load("four_bar")
    >>> inf = mb.influence(mech, mb.forward_kinematics(mech, np.array([0.2])).q)
    >>> inf.G.shape, inf.dG.shape, inf.n_passive
    ((3, 1), (3, 1, 1), 2)
    """
    mech = check_mechanism(mech)
    second_order = check_bool(second_order, "second_order")
    qf, batch = _flat(mech, q)
    npas = mech.tree.nv - len(mech.tree.act_dof)

    from ._compiled import compiled_influence  # numba loads on the first kernel call

    model = compile_model(mech)

    def run(qs: np.ndarray) -> tuple:
        G, dG, _, rank, cons, smin, cond = compiled_influence(model, qs, second_order)
        return (G, rank, cons, smin, cond) + (() if dG is None else (dG,))

    res = on_rows(failed_rows(qf), run, qf, probe=(mech.tree.q0[None],))
    G, rank, cons, smin, cond = res[:5]
    dG = res[5] if len(res) > 5 else None
    nv, na = G.shape[-2:]
    return Influence(
        G=G.reshape(*batch, nv, na),
        dG=None if dG is None else dG.reshape(*batch, nv, na, na),
        passive_rank=rank.reshape(batch),
        n_passive=npas,
        consistency=cons.reshape(batch),
        sigma_min=smin.reshape(batch),
        cond=cond.reshape(batch),
    )


def site_pose(mech: Mechanism, q: object, site: str) -> np.ndarray:
    """World pose ``T (..., 4, 4)`` of ``site`` at ``q (..., nq)`` (any q: tree kinematics, no closure).

    Parameters
    ----------
    mech : Mechanism
        The described mechanism.
    q : array_like, shape (..., nq)
        Configurations (MuJoCo ``qpos``, ``[w, x, y, z]`` quaternions for ball/free joints); the
        closures are not imposed, so an unassembled ``q`` gives the spanning tree's pose.
    site : str
        Name of a site of ``mech``.

    Returns
    -------
    ndarray, shape (..., 4, 4)
        ``T_WS``, the site frame in the world frame (translation in m).

    Raises
    ------
    ValueError
        If ``mech`` is not a Mechanism, ``site`` is not a site name, or ``q`` is not finite real of shape
        ``(..., nq)``.

    Examples
    --------
    >>> import numpy as np
    >>> from robomech import multibody as mb
    >>> mech = mb.gallery.load("four_bar")
    >>> mb.site_pose(mech, np.zeros((5, mech.nq)), "coupler_point").shape
    (5, 4, 4)
    """
    mech = check_mechanism(mech)
    si = _site_index(mech, site)
    qf, batch = _flat(mech, q)
    from ._compiled import compiled_site_pose  # numba loads on the first kernel call

    model = compile_model(mech)
    (T,) = on_rows(
        failed_rows(qf),
        lambda qs: (compiled_site_pose(model, qs, si),),
        qf,
        probe=(mech.tree.q0[None],),
    )
    return T.reshape(*batch, 4, 4)


def site_jacobian(mech: Mechanism, q: object, site: str) -> np.ndarray:
    """``[ω; ṗ] = J qd_act`` for ``site`` at assembled ``q (..., nq)``: ``(..., 6, n_act)`` (mj_jacSite).

    ``J = J_f G``: the site's frame Jacobian over every velocity coordinate times the first-order
    influence coefficients (:func:`influence`), so that ``J`` maps the actuated rates alone.

    Parameters
    ----------
    mech : Mechanism
        The described mechanism.
    q : array_like, shape (..., nq)
        Assembled configurations (MuJoCo ``qpos``, e.g. ``forward_kinematics(mech, q_act).q``).
    site : str
        Name of a site of ``mech``.

    Returns
    -------
    ndarray, shape (..., 6, n_act)
        Rows ``[ω; ṗ]`` in world axes: angular velocity (rad/s) and the velocity of the site point (m/s)
        per unit rate of each actuated joint (rad/s or m/s), columns in actuator order.

    Raises
    ------
    ValueError
        If ``mech`` is not a Mechanism, ``site`` is not a site name, or ``q`` is not finite real of shape
        ``(..., nq)``.

    Examples
    --------
    >>> import numpy as np
    >>> from robomech import multibody as mb
    >>> mech = mb.gallery.load("four_bar")
    >>> q = mb.forward_kinematics(mech, np.array([0.2])).q
    >>> mb.site_jacobian(mech, q, "coupler_point").shape
    (6, 1)
    """
    mech = check_mechanism(mech)
    si = _site_index(mech, site)
    qf, batch = _flat(mech, q)
    from ._compiled import compiled_site_jacobian  # numba loads on the first kernel call

    (J,) = on_rows(
        failed_rows(qf), lambda qs: (compiled_site_jacobian(mech, qs, si),), qf, probe=(mech.tree.q0[None],)
    )
    return J.reshape(*batch, 6, J.shape[-1])


def site_hessian(mech: Mechanism, q: object, site: str) -> np.ndarray:
    """``H[..., i, j, k] = ∂J[..., i, j]/∂q_act,k`` for ``site`` at assembled ``q``: (..., 6, n_act, n_act).

    ``[ω̇; p̈] = J qdd_act + einsum("...ijk,...j,...k->...i", H, qd_act, qd_act)``.  Exact:
    ``∂J/∂q_act,k = (dJ_f/dt) G + J_f ∂G/∂q_act,k`` along ``qd = G e_k`` (module docstring).

    Parameters
    ----------
    mech : Mechanism
        The described mechanism.
    q : array_like, shape (..., nq)
        Assembled configurations (MuJoCo ``qpos``).
    site : str
        Name of a site of ``mech``.

    Returns
    -------
    ndarray, shape (..., 6, n_act, n_act)
        Rows ``[ω; ṗ]`` as in :func:`site_jacobian` (world axes; rad and m per unit input squared);
        ``(..., 6, 0, 0)`` for a mechanism without actuators.

    Raises
    ------
    ValueError
        If ``mech`` is not a Mechanism, ``site`` is not a site name, or ``q`` is not finite real of shape
        ``(..., nq)``.

    Examples
    --------
    >>> import numpy as np
    >>> from robomech import multibody as mb
    >>> mech = mb.gallery.load("four_bar")
    >>> q = mb.forward_kinematics(mech, np.array([0.2])).q
    >>> mb.site_hessian(mech, q, "coupler_point").shape
    (6, 1, 1)
    """
    mech = check_mechanism(mech)
    si = _site_index(mech, site)
    qf, batch = _flat(mech, q)
    na = len(mech.tree.act_dof)
    if na == 0:
        return np.zeros((*batch, 6, 0, 0))

    from ._compiled import compiled_influence  # numba loads on the first kernel call

    model = compile_model(mech)

    def run(qs: np.ndarray) -> tuple:
        return (compiled_influence(model, qs, True, si)[2],)

    (H,) = on_rows(failed_rows(qf), run, qf, probe=(mech.tree.q0[None],))
    return H.reshape(*batch, 6, na, na)


def constraint_residual(mech: Mechanism, q: object) -> np.ndarray:
    """Closure residual ``(..., m)`` in length units (rotation rows times the characteristic length).

    Parameters
    ----------
    mech : Mechanism
        The described mechanism.
    q : array_like, shape (..., nq)
        Configurations (MuJoCo ``qpos``); any, assembled or not.

    Returns
    -------
    ndarray, shape (..., m)
        One entry per closure constraint row (m rows over all closures), in m; zero where every
        closure is assembled.

    Raises
    ------
    ValueError
        If ``mech`` is not a Mechanism or ``q`` is not finite real of shape ``(..., nq)``.

    Examples
    --------
    >>> import numpy as np
    >>> from robomech import multibody as mb
    >>> mech = mb.gallery.load("four_bar")
    >>> q = mb.forward_kinematics(mech, np.array([0.2])).q
    >>> bool(np.max(np.abs(mb.constraint_residual(mech, q))) < 1e-9)
    True
    """
    from ._compiled import compiled_resjac  # numba loads on the first kernel call

    mech = check_mechanism(mech)
    qf, batch = _flat(mech, q)
    model = compile_model(mech)
    (r,) = on_rows(
        failed_rows(qf),
        lambda qs: (compiled_resjac(model, qs, False)[0],),
        qf,
        probe=(mech.tree.q0[None],),
    )
    return r.reshape(*batch, r.shape[-1])


def constraint_jacobian(mech: Mechanism, q: object) -> np.ndarray:
    """Velocity constraint matrix ``K (..., m, nv)``: admissible ``qd`` (qvel) satisfy ``K qd = 0``.

    Parameters
    ----------
    mech : Mechanism
        The described mechanism.
    q : array_like, shape (..., nq)
        Configurations (MuJoCo ``qpos``), normally assembled.

    Returns
    -------
    ndarray, shape (..., m, nv)
        Rows as in :func:`constraint_residual` (length units), one column per velocity coordinate
        (MuJoCo ``qvel``; local angular velocity for ball joints).

    Raises
    ------
    ValueError
        If ``mech`` is not a Mechanism or ``q`` is not finite real of shape ``(..., nq)``.

    Examples
    --------
    >>> import numpy as np
    >>> from robomech import multibody as mb
    >>> mech = mb.gallery.load("four_bar")
    >>> q = mb.forward_kinematics(mech, np.array([0.2])).q
    >>> K = mb.constraint_jacobian(mech, q)
    >>> K.shape, bool(np.allclose(K @ mb.influence(mech, q).G, 0.0))
    ((3, 3), True)
    """
    from ._compiled import compiled_resjac  # numba loads on the first kernel call

    mech = check_mechanism(mech)
    qf, batch = _flat(mech, q)
    model = compile_model(mech)
    (K,) = on_rows(
        failed_rows(qf),
        lambda qs: (compiled_resjac(model, qs, True)[1],),
        qf,
        probe=(mech.tree.q0[None],),
    )
    return K.reshape(*batch, *K.shape[1:])


def constraint_jacobian_rate(mech: Mechanism, q: object, qd: object) -> np.ndarray:
    """``dK/dt (..., m, nv)`` along ``qd (..., nv)``: ``K qdd + dK/dt qd = 0`` for admissible motions.

    Parameters
    ----------
    mech : Mechanism
        The described mechanism.
    q : array_like, shape (..., nq)
        Configurations (MuJoCo ``qpos``), normally assembled.
    qd : array_like, shape (..., nv)
        Rate of every velocity coordinate (``qvel``; rad/s, m/s).  Batch dimensions of ``q`` and
        ``qd`` broadcast.

    Returns
    -------
    ndarray, shape (..., m, nv)
        Time derivative of :func:`constraint_jacobian` along the motion ``qd`` (length units per s).

    Raises
    ------
    ValueError
        If ``mech`` is not a Mechanism, ``q`` or ``qd`` is not finite real of the shape above, or their batch
        shapes do not broadcast.

    Examples
    --------
    >>> import numpy as np
    >>> from robomech import multibody as mb
    >>> mech = mb.gallery.load("four_bar")
    >>> q = mb.forward_kinematics(mech, np.array([0.2])).q
    >>> mb.constraint_jacobian_rate(mech, q, np.zeros(mech.nv)).shape
    (3, 3)
    """
    mech = check_mechanism(mech)
    q = check_q(mech, q, nan_rows=True)
    qd = as_array(qd, "qd", (mech.nv,))
    batch = broadcast_batch((q, 1, "q"), (qd, 1, "qd"))
    qf = np.broadcast_to(q, (*batch, mech.nq)).reshape(-1, mech.nq)
    qdf = np.broadcast_to(qd, (*batch, mech.nv)).reshape(-1, mech.nv)

    from ._compiled import compiled_jacobian_rate  # numba loads on the first kernel call

    model = compile_model(mech)

    def run(qs: np.ndarray, qds: np.ndarray) -> tuple:
        return (compiled_jacobian_rate(model, qs, qds),)

    (Kd,) = on_rows(failed_rows(qf), run, qf, qdf, probe=(mech.tree.q0[None], qdf[:1]))
    return Kd.reshape(*batch, *Kd.shape[1:])
