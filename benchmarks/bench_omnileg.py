"""OmniLeg (paper 2) workloads for issue 9: kinematics over 10^6 samples, inverse dynamics over 10^5.

Alternatives: the per-sample Python loop over the same robomech function, and for the inverse dynamics
the per-sample loop of MuJoCo's inverse dynamics on the same mechanism (``mj_forward`` for the
constraint Jacobian, ``mj_inverse`` of the tree, least-squares projection onto the three motors).
"""

from __future__ import annotations

from functools import cache

import numpy as np

import robomech.mechanisms.omnileg as ol

from _harness import Workload

N_KIN = 1_000_000
N_DYN = 100_000
N_ALT_KIN = 2000
N_ALT_DYN = 2000
N_ALT_ENGINE = 200
# Generic (robomech.multibody) vs analytic inverse dynamics of the same description (issue 13).
N_GEN = 10_000
LEG = ol.OmniLeg.paper()


@cache
def _kin_data() -> tuple[np.ndarray, np.ndarray]:
    rng = np.random.default_rng(0)
    q = np.stack(
        [
            rng.uniform(-1, 1, N_KIN) * LEG.alpha_max,
            rng.uniform(-1, 1, N_KIN) * LEG.beta_max,
            rng.uniform(LEG.gamma_min, LEG.gamma_max, N_KIN),
        ],
        axis=-1,
    )
    return q, ol.forward_kinematics(LEG, q)


@cache
def _dyn_data():
    t = np.linspace(0.0, 6.0, N_DYN)
    prof = ol.joint_trajectory_eq52(t)
    F = np.where((t <= 1.0)[:, None], np.array([0.0, -20.0, 20.0]), 0.0)
    return prof.q, prof.qd, prof.qdd, F


@cache
def _engine():
    from robomech.verify import omnileg as vo  # MuJoCo only for this alternative

    q, qd, qdd, F = _dyn_data()
    idx = np.linspace(0, N_DYN - 1, N_ALT_ENGINE).astype(int)
    jm = ol.joint_motion(LEG, q[idx], qd[idx], qdd[idx])
    return vo, vo.build_model(LEG), jm, F[idx]


@cache
def _generic_data():
    """The description and assembled q of N_GEN samples of eq. (52) (qpos from joint_motion: same joints)."""
    q, qd, qdd, F = (a[:: N_DYN // N_GEN] for a in _dyn_data())
    mech = ol.to_multibody(LEG)
    qpos = np.zeros((len(q), mech.nq))
    qpos[:, [mech.qpos_address(n) for n in ol.TREE_JOINTS]] = ol.joint_motion(LEG, q, qd, qdd).q
    W = np.zeros((len(q), 6))
    W[:, 3:] = F
    return mech, qpos, q, qd, qdd, F, W


def _generic_dyn():
    from robomech import multibody as mb

    mech, qpos, _, qd, qdd, _, W = _generic_data()
    return mb.inverse_dynamics(mech, qpos, qd, qdd, wrenches={"foot": W})


def _analytic_dyn_gen():
    _, _, q, qd, qdd, F, _ = _generic_data()
    return ol.inverse_dynamics(LEG, q, qd, qdd, foot_force=F)


def _engine_loop() -> np.ndarray:
    vo, em, jm, F = _engine()
    return vo.engine_inverse_dynamics(em, jm, F)


def _loop(fn, *arrays, n):
    return [fn(LEG, *(a[i] for a in arrays)) for i in range(n)]


def workloads() -> list[Workload]:
    f8 = 8
    kin = [
        ("omnileg: forward kinematics (eq. 11)", lambda: ol.forward_kinematics(LEG, _kin_data()[0]),
         lambda: _loop(ol.forward_kinematics, _kin_data()[0], n=N_ALT_KIN), 6 * f8),
        ("omnileg: inverse kinematics (eq. 13 corr.)", lambda: ol.inverse_kinematics(LEG, _kin_data()[1]),
         lambda: _loop(ol.inverse_kinematics, _kin_data()[1], n=N_ALT_KIN), 6 * f8 + 3),
        ("omnileg: foot Jacobian (eq. 14)", lambda: ol.jacobian(LEG, _kin_data()[0]),
         lambda: _loop(ol.jacobian, _kin_data()[0], n=N_ALT_KIN), 12 * f8),
    ]  # fmt: skip
    out = [
        Workload(name=name, group="2", run=run, n=N_KIN, bytes_moved=N_KIN * per, alternative=alt,
                 n_alt=N_ALT_KIN, alternative_name="per-sample Python loop", target_speedup=100.0,
                 target_floor_ratio=20.0)
        for name, run, alt, per in kin
    ]  # fmt: skip
    dyn_bytes = N_DYN * f8 * (4 * 3 + 4 * 3 + 9)  # q, q̇, q̈, F in; τ and its 3 parts + M out

    def dyn():
        return ol.inverse_dynamics(LEG, *_dyn_data()[:3], foot_force=_dyn_data()[3])

    def dyn_loop():
        q, qd, qdd, F = _dyn_data()
        return [ol.inverse_dynamics(LEG, q[i], qd[i], qdd[i], foot_force=F[i]) for i in range(N_ALT_DYN)]

    out.append(Workload(name="omnileg: inverse dynamics, eq. (52)", group="3", run=dyn, n=N_DYN,
                        bytes_moved=dyn_bytes, alternative=_engine_loop, n_alt=N_ALT_ENGINE,
                        alternative_name="MuJoCo ID per-sample loop", target_speedup=5.0,
                        repeats=2))  # fmt: skip
    out.append(Workload(name="omnileg: inverse dynamics (vs own loop)", group="3", run=dyn, n=N_DYN,
                        bytes_moved=dyn_bytes, alternative=dyn_loop, n_alt=N_ALT_DYN,
                        alternative_name="per-sample Python loop", repeats=2))  # fmt: skip
    # issue 13: "the generic OmniLeg within 3x of the analytic one" (speed-up target 1/3)
    gen_bytes = N_GEN * f8 * (22 + 3 * 3 + 6 + 3 * 5 + 9)  # qpos, rates, wrench in; τ, parts, M_a out
    out.append(Workload(name="omnileg: generic inverse dynamics (vs analytic)", group="3", run=_generic_dyn,
                        n=N_GEN, bytes_moved=gen_bytes, alternative=_analytic_dyn_gen, n_alt=N_GEN,
                        alternative_name="analytic Lagrange model (batched)", target_speedup=1 / 3,
                        repeats=2))  # fmt: skip
    return out
