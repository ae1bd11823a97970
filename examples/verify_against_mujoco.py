"""
Verify your own mechanism against an independent engine (MuJoCo)
================================================================

The offset slider-crank of the Builder example, now with masses, is exported to MJCF and handed
to ``robomech verify``: MuJoCo compiles the file and its own routines (``mj_kinematics``,
``mj_rne``, the constraint solver, the integrator) are compared with robomech's closure,
velocities, accelerations, inverse dynamics, energy and a forward simulation.  The exit code is 0
when every check passes.  Needs the ``verify`` extra (``pip install "robomech[verify]"``).
"""

import sys
import tempfile
from pathlib import Path

import numpy as np

from robomech import multibody as mb
from robomech.cli import main

R, L = 0.1, 0.3  # crank and rod lengths (m)
ROD0 = -0.4  # rod angle at the reference pose (rad)
X0, E = R + L * np.cos(ROD0), L * np.sin(ROD0)

b = mb.Builder("slider_crank", gravity=(0.0, -9.81, 0.0))
b.body("crank", joints=[b.hinge("phi", axis=(0, 0, 1))],
       inertial=mb.Inertial(0.2, pos=(R / 2, 0, 0), diaginertia=(1e-5, 2e-4, 2e-4)))
b.body("rod", parent="crank", pos=(R, 0, 0), quat=(np.cos(ROD0 / 2), 0, 0, np.sin(ROD0 / 2)),
       joints=[b.hinge("psi", axis=(0, 0, 1))],
       inertial=mb.Inertial(0.5, pos=(L / 2, 0, 0), diaginertia=(1e-5, 3.75e-3, 3.75e-3)))
b.body("slider", pos=(X0, E, 0), joints=[b.slide("s", axis=(1, 0, 0))],
       inertial=mb.Inertial(1.0, diaginertia=(1e-3, 1e-3, 1e-3)))
b.connect("pin", "rod", "slider", anchor1=(L, 0, 0))
b.site("piston", "slider")
b.actuate("phi")
mech = b.build()

with tempfile.TemporaryDirectory() as tmp:
    path = Path(tmp) / "slider_crank.xml"
    path.write_text(mb.to_mjcf(mech))
    code = main(["verify", str(path)])  # prints the table of checks
print("exit code", code)
if code != 0:
    sys.exit(code)
print("OK")
