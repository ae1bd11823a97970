"""
Inverse dynamics of a closed chain
==================================

The crank torque that drives an offset slider-crank.

The crank follows a rest-to-rest quintic (``robomech.trajectory``) through half a turn in 0.5 s,
with gravity along -y in the mechanism's plane.  ``multibody.inverse_dynamics`` gives the crank
torque of the closed chain (tree dynamics projected through the loop's influence coefficients); it
is checked by the power balance ``tau * dphi/dt = dE/dt``, with the energy ``E = T + U`` computed
separately (``multibody.energy``) and differentiated numerically.
"""

import numpy as np

from robomech import multibody as mb
from robomech.trajectory import quintic

R, L = 0.1, 0.3  # crank and rod lengths (m)
ROD0 = -0.4  # rod angle at the reference pose (rad)
X0, E = R + L * np.cos(ROD0), L * np.sin(ROD0)
DURATION = 0.5  # s
# dE/dt by a central difference with h = 1e-5 s: truncation ~h^2 E''' and rounding ~1e-16 E / h,
# both below 1e-7 of the peak power here.
POWER_RTOL = 1e-6

b = mb.Builder("slider_crank", gravity=(0.0, -9.81, 0.0))
rod_inertia = mb.Inertial(0.5, pos=(L / 2, 0, 0), diaginertia=(1e-5, 0.5 * L**2 / 12, 0.5 * L**2 / 12))
b.body("crank", joints=[b.hinge("phi", axis=(0, 0, 1))],
       inertial=mb.Inertial(0.2, pos=(R / 2, 0, 0), diaginertia=(1e-5, 2e-4, 2e-4)))
b.body("rod", parent="crank", pos=(R, 0, 0), quat=(np.cos(ROD0 / 2), 0, 0, np.sin(ROD0 / 2)),
       joints=[b.hinge("psi", axis=(0, 0, 1))], inertial=rod_inertia)
b.body("slider", pos=(X0, E, 0), joints=[b.slide("s", axis=(1, 0, 0))],
       inertial=mb.Inertial(1.0, diaginertia=(1e-3, 1e-3, 1e-3)))
b.connect("pin", "rod", "slider", anchor1=(L, 0, 0))
b.actuate("phi")
mech = b.build()


def motion(t: np.ndarray):
    """Assembled configuration, crank rate and acceleration at the times t (s)."""
    p = quintic(t, DURATION, start=0.0, end=np.pi)  # crank angle (rad)
    fk = mb.forward_kinematics(mech, p.q[:, None], steps=8)
    assert fk.converged.all()
    return fk.q, p.qd[:, None], p.qdd[:, None]


t = np.linspace(0.05, 0.45, 9)
q, qd, qdd = motion(t)
res = mb.inverse_dynamics(mech, q, qd, qdd)
assert res.valid.all()
tau = res.tau[:, 0]  # N m

h = 1e-5


def total_energy(ts: np.ndarray) -> np.ndarray:
    qs, qds, qdds = motion(ts)
    rates = mb.inverse_dynamics(mech, qs, qds, qdds).qd  # every coordinate's rate
    T, U = mb.energy(mech, qs, rates)
    return T + U


dEdt = (total_energy(t + h) - total_energy(t - h)) / (2 * h)
power = tau * qd[:, 0]
rel = np.max(np.abs(power - dEdt)) / np.max(np.abs(power))
for ti, ta, pw in zip(t, tau, power, strict=True):
    print(f"  t = {ti:.2f} s   tau = {ta:+.4f} N m   power = {pw:+.4f} W")
print(f"power balance tau * dphi/dt vs dE/dt: max relative error {rel:.1e}")
assert rel < POWER_RTOL

# The crank torque along the motion, and the power balance it satisfies.
import matplotlib.pyplot as plt  # noqa: E402

fig, (a1, a2) = plt.subplots(2, 1, figsize=(6, 5), sharex=True)
a1.plot(t, tau, "o-")
a1.set_ylabel("crank torque (N m)")
a2.plot(t, power, "o-", label="tau * dphi/dt")
a2.plot(t, dEdt, "k+", ms=10, label="dE/dt (central difference)")
a2.set_xlabel("time (s)")
a2.set_ylabel("power (W)")
a2.legend()
print("OK")
