"""Issue 9 workloads for paper 5 (vectored thruster): IK, FK, Jacobian over 10^6 samples; a 10^6 map."""

from __future__ import annotations

import numpy as np

from robomech.mechanisms import vectored_thrust as vt

from _harness import Workload

N = 1_000_000
N_ALT = 2000  # per-sample Python loop timed on this many samples and scaled
# Best of this many runs for the 30-40 ms kernels: on the shared 2-core machine single runs vary 1.5-2x
# with the other processes' load (the harness's default is 3).
REPEATS = 5


def workloads() -> list[Workload]:
    th = vt.VectoredThruster.paper()
    rng = np.random.default_rng(0)
    q = rng.uniform([th.q1_limits[0], th.q2_limits[0]], [th.q1_limits[1], th.q2_limits[1]], size=(N, 2))
    s = vt.forward_kinematics(th, q).axis
    g = vt.input_grid(th, 1000)  # 10^6-sample input grid for the map
    qa, sa = q[:N_ALT], s[:N_ALT]
    b = 8  # float64 bytes
    return [
        Workload(
            name="vectored_thrust: forward kinematics",
            group="2",
            run=lambda: vt.forward_kinematics(th, q),
            n=N,
            bytes_moved=N * (2 * b + 3 * b + 3 * b + b + 4),  # q in; axis, tip, tilt, 4 masks out
            alternative=lambda: [vt.forward_kinematics(th, x) for x in qa],
            n_alt=N_ALT,
            alternative_name="per-sample loop, same function",
            target_speedup=100,
            target_floor_ratio=20,
            repeats=REPEATS,
        ),
        Workload(
            name="vectored_thrust: inverse kinematics",
            group="2",
            run=lambda: vt.inverse_kinematics(th, s),
            n=N,
            bytes_moved=N * (3 * b + 2 * b + 4),  # axis in; q, 4 masks out
            alternative=lambda: [vt.inverse_kinematics(th, x) for x in sa],
            n_alt=N_ALT,
            alternative_name="per-sample loop, same function",
            target_speedup=100,
            target_floor_ratio=20,
            repeats=REPEATS,
        ),
        Workload(
            name="vectored_thrust: Jacobian",
            group="2",
            run=lambda: vt.jacobian(th, q),
            n=N,
            bytes_moved=N * (2 * b + 6 * b + b + 1),  # q in; J, distance, valid out
            alternative=lambda: [vt.jacobian(th, x) for x in qa],
            n_alt=N_ALT,
            alternative_name="per-sample loop, same function",
            target_speedup=100,
            target_floor_ratio=20,
            repeats=REPEATS,
        ),
        Workload(
            name="vectored_thrust: workspace/singularity map",
            group="5",
            run=lambda: vt.workspace_map(th, g),
            n=N,
            # q in; tip, tilt, clearance, distance, dexterity and 5 masks out
            bytes_moved=N * (2 * b + 3 * b + 4 * b + 5),
            alternative=lambda: [vt.workspace_map(th, x) for x in g.reshape(-1, 2)[:N_ALT]],
            n_alt=N_ALT,
            alternative_name="per-sample loop, same function",
            target_speedup=100,
            repeats=1,
        ),
    ]
