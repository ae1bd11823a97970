"""A user's Delta robot (three arms, parallelogram forearms), described with the multibody Builder.

``build(arm, forearm, R, r)``: arm length ``arm``, forearm (rod) length ``forearm``, base radius ``R`` and
platform radius ``r`` (m); arm masses 0.2 kg, rods 0.02 kg each, platform with payload 0.3 kg.  The
reference configuration has every arm 30 degrees below the horizontal.  ``pick_and_place()`` is a
0.5 s pick-and-place path of the platform's ``tcp`` (21 samples); ``study()`` the design study of peak and
RMS actuator force along it over the four lengths (the tests and ``benchmarks/bench_model_study.py``)::

    robomech sweep --model examples/models/delta.py:build ... (Python: see docs/explore.md)
"""

import numpy as np

from robomech.multibody import Builder, Inertial

THETA0 = np.deg2rad(30.0)
HALF_WIDTH = 0.03  # half the parallelogram's width (m)
ARM_MASS, ROD_MASS, PLATFORM_MASS = 0.2, 0.02, 0.3  # kg


def _quat(R):
    w = np.sqrt(max(0.0, 1.0 + R[0, 0] + R[1, 1] + R[2, 2])) / 2
    if w > 1e-8:
        return (
            w,
            (R[2, 1] - R[1, 2]) / (4 * w),
            (R[0, 2] - R[2, 0]) / (4 * w),
            (R[1, 0] - R[0, 1]) / (4 * w),
        )
    from scipy.spatial.transform import Rotation

    x, y, z, w = Rotation.from_matrix(R).as_quat()
    return (w, x, y, z)


def _frame_x(x, y_hint):
    x = x / np.linalg.norm(x)
    z = np.cross(x, y_hint)
    z /= np.linalg.norm(z)
    return np.column_stack([x, np.cross(z, x), z])


def height(arm, forearm, R, r, theta=THETA0):
    """Depth of the platform below the base at equal arm angles theta (closed form)."""
    return arm * np.sin(theta) + np.sqrt(forearm**2 - (R + arm * np.cos(theta) - r) ** 2)


def build(arm=0.25, forearm=0.6, R=0.2, r=0.05):
    if not forearm > abs(R + arm * np.cos(THETA0) - r):
        raise ValueError("Expected the forearms to reach the platform in the reference configuration.")
    p = np.array([0.0, 0.0, -height(arm, forearm, R, r)])
    b = Builder("delta", gravity=(0, 0, -9.81))
    b.body(
        "platform",
        pos=p,
        joints=[b.free("platform")],
        inertial=Inertial(PLATFORM_MASS, diaginertia=(1e-4, 1e-4, 2e-4)),
    )
    for i in range(3):
        g = 2 * np.pi / 3 * i
        er, t, ez = (
            np.array([np.cos(g), np.sin(g), 0.0]),
            np.array([-np.sin(g), np.cos(g), 0.0]),
            np.eye(3)[2],
        )
        c, s_ = np.cos(THETA0), np.sin(THETA0)
        R_arm = np.column_stack([er, t, ez]) @ np.array([[c, 0, s_], [0, 1, 0], [-s_, 0, c]])
        name = f"arm{i + 1}"
        Ia = ARM_MASS * arm**2 / 12
        b.body(
            name,
            pos=R * er,
            quat=_quat(R_arm),
            joints=[b.hinge(f"theta{i + 1}", axis=(0, 1, 0), ref=THETA0)],
            inertial=Inertial(ARM_MASS, pos=(arm / 2, 0, 0), diaginertia=(1e-6, Ia, Ia)),
        )
        J = R * er + arm * R_arm[:, 0]
        E = p + r * er
        for side, s in (("a", 1.0), ("b", -1.0)):
            top, bot = J + s * HALF_WIDTH * t, E + s * HALF_WIDTH * t
            R_rod = _frame_x(bot - top, t)
            rod = f"rod{i + 1}{side}"
            Ir = ROD_MASS * forearm**2 / 12
            b.body(
                rod,
                name,
                pos=(arm, s * HALF_WIDTH, 0.0),
                quat=_quat(R_arm.T @ R_rod),
                joints=[b.ball(f"upper{i + 1}{side}")],
                inertial=Inertial(ROD_MASS, pos=(forearm / 2, 0, 0), diaginertia=(1e-7, Ir, Ir)),
            )
            b.connect(f"lower{i + 1}{side}", rod, "platform", anchor1=(forearm, 0.0, 0.0), anchor2=bot - p)
    b.site("tcp", "platform")
    b.actuate("theta1", "theta2", "theta3")
    return b.build()


def pick_and_place(z=-0.6, span=0.2, lift=0.05, duration=0.5, samples=21):
    """``(t (T,), points (T, 3))``: across ``span`` in x with a ``lift`` arc in z, cosine time law."""
    t = np.linspace(0.0, duration, samples)
    s = (1 - np.cos(np.pi * t / duration)) / 2
    pts = np.stack([-span / 2 + span * s, np.zeros_like(s), z + lift * np.sin(np.pi * s)], -1)
    return t, pts


def study():
    """Peak and RMS actuator force along ``pick_and_place()`` over arm, forearm, R and r (m)."""
    from robomech.explore import Variable, load_model, model_study

    return model_study(
        load_model(f"{__file__}:build"),
        [
            Variable("arm", 0.2, 0.3, "m"),
            Variable("forearm", 0.5, 0.7, "m"),
            Variable("R", 0.15, 0.25, "m"),
            Variable("r", 0.04, 0.06, "m"),
        ],
        site="tcp",
        outputs="xyz",
        metrics=("peak_force", "rms_force"),
        trajectory=pick_and_place(),
    )
