"""Issue 9 workloads of paper 1 (spherical parallel leg): IK, FK, Jacobian over 10^6 poses, inverse
dynamics along a 10^5-sample trajectory vs a per-sample loop of MuJoCo's inverse dynamics of the same
mechanism, and a 10^6-sample workspace/singularity map.

The forward kinematics runs in compiled (numba) kernels; their
one-off compile cost (then cached on disk) is measured in a fresh process with an empty cache and printed.
"""

from __future__ import annotations

import numpy as np

from robomech.mechanisms import spherical_leg as sl

from _harness import Workload, fresh_process_seconds

N_KIN = 1_000_000
N_DYN = 100_000
N_ALT = 2_000
N_ALT_ENGINE = 500


def _fk_compile_seconds() -> float:
    """First large-batch FK call in a fresh process with an empty numba cache, minus a second call."""
    return fresh_process_seconds(
        "import time, numpy as np; from robomech.mechanisms import spherical_leg as sl; "
        "n = 4096; "
        "leg = sl.SphericalLeg.paper(); L = sl.inverse_kinematics(leg, np.zeros(n), np.zeros(n)).lengths; "
        "t = time.perf_counter(); sl.forward_kinematics(leg, L); t1 = time.perf_counter(); "
        "sl.forward_kinematics(leg, L); print((t1 - t) - (time.perf_counter() - t1))"
    )


def workloads() -> list[Workload]:
    compile_s = _fk_compile_seconds()
    print(f"spherical_leg FK kernels: compile on first use {compile_s:.1f} s (then cached on disk)")
    leg = sl.SphericalLeg.paper()
    rng = np.random.default_rng(0)
    q = rng.uniform(-1.0, 1.0, (N_KIN, 2))
    a, b = q[:, 0].copy(), q[:, 1].copy()
    ik = sl.inverse_kinematics(leg, a, b)
    L = ik.lengths + rng.normal(scale=1e-5, size=(N_KIN, 3))  # 10 µm measurement noise: a real fit
    f8 = 8
    ik_bytes = (2 + 3 + 9 + 9) * N_KIN * f8 + 3 * N_KIN  # inputs, lengths, unit vectors, points, mask
    fk_bytes = (3 + 3) * N_KIN * f8 + 2 * N_KIN
    jac_bytes = (2 + 6) * N_KIN * f8
    ws_bytes = (2 + 3 + 4) * N_KIN * f8 + 3 * N_KIN

    t = np.linspace(0.0, 25.0, N_DYN)
    qt, qdt, qddt = sl.fig5_motion("b", t)
    dyn_bytes = (6 + 2 + 3 + 1) * N_DYN * f8 + N_DYN

    def loop(fn, n):
        def run():
            for k in range(n):
                fn(k)

        return run

    out = [
        Workload(
            "spherical_leg: inverse kinematics (lengths, axes, points)",
            "2",
            lambda: sl.inverse_kinematics(leg, a, b),
            N_KIN,
            ik_bytes,
            loop(lambda k: sl.inverse_kinematics(leg, a[k], b[k]), N_ALT),
            N_ALT,
            "per-sample loop, same fn",
            100.0,
            20.0,
        ),
        Workload(
            "spherical_leg: forward kinematics (noisy, lstsq)",
            "2",
            lambda: sl.forward_kinematics(leg, L),
            N_KIN,
            fk_bytes,
            loop(lambda k: sl.forward_kinematics(leg, L[k]), N_ALT),
            N_ALT,
            "per-sample loop, same fn",
            100.0,
            20.0,
        ),
        Workload(
            "spherical_leg: Jacobian dl/d(alpha, beta)",
            "2",
            lambda: sl.jacobian(leg, a, b),
            N_KIN,
            jac_bytes,
            loop(lambda k: sl.jacobian(leg, a[k], b[k]), N_ALT),
            N_ALT,
            "per-sample loop, same fn",
            100.0,
            20.0,
        ),
        Workload(
            "spherical_leg: workspace/singularity map",
            "5",
            lambda: sl.workspace_map(leg, a, b),
            N_KIN,
            ws_bytes,
            loop(lambda k: sl.workspace_map(leg, a[k], b[k]), N_ALT),
            N_ALT,
            "per-sample loop, same fn",
            None,
            20.0,
        ),
    ]
    try:
        from robomech.verify import spherical_leg as vsl
    except ImportError:  # MuJoCo is the optional 'verify' extra
        vsl = None
    dyn = lambda: sl.inverse_dynamics(leg, qt, qdt, qddt, driven_legs=sl.PAPER_DRIVEN_LEGS)  # noqa: E731
    if vsl is not None:
        idx = np.linspace(0, N_DYN - 1, N_ALT_ENGINE).astype(int)
        alt = lambda: vsl.inverse_dynamics_engine(leg, qt[idx], qdt[idx], qddt[idx])  # noqa: E731
        out.append(
            Workload(
                "spherical_leg: inverse dynamics, Fig. 5(b) trajectory",
                "3",
                dyn,
                N_DYN,
                dyn_bytes,
                alt,
                N_ALT_ENGINE,
                "MuJoCo mj_rne + lstsq loop",
                5.0,
                None,
            )
        )
    else:
        out.append(
            Workload("spherical_leg: inverse dynamics, Fig. 5(b) trajectory", "3", dyn, N_DYN, dyn_bytes)
        )
    return out
