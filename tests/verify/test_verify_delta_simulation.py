"""The Delta's forward simulation against MuJoCo, in the suite.

``robomech verify delta`` simulates the passive Delta (27 coordinates) for T_SIM = 0.3 s, which takes
~8 s of CPU (20-60 s on a busy machine) and is therefore left out of
``test_large_gallery_mechanism_agrees_with_engine``.  Half that horizon exercises the same code (the
multibody integration on the constraint manifold, the engine's soft-constraint stepping, the comparison)
for ~1.5 s of CPU.  Its samples lie on the engine's 0.1 ms step grid, so the engine is read at exactly
the simulated times.
"""

from __future__ import annotations

import pytest

from robomech import multibody as mb
from robomech.verify import _generic as g
from robomech.verify._mujoco import assemble_along

# Half of the CLI's horizon; a multiple of (SIM_SAMPLES - 1) * SIM_TIMESTEP: the samples fall on engine steps.
T_SHORT = 0.15
# The motion must be large enough for the relative error to mean something (0.385 rad measured).
MIN_MOTION = 0.1


@pytest.mark.slow
def test_delta_passive_simulation_tracks_the_engine():
    mech = mb.gallery.load("delta")
    drv = g._driver(mech)
    t, at = g.trajectory(drv)
    qa, qda, _ = at(t[:1])
    fk = assemble_along(drv, qa)
    q, conv = fk.q, fk.converged
    assert conv.all()
    checks = g._simulation_checks(mech, "delta", q[0], qda[0], duration=T_SHORT)
    assert [c.quantity for c in checks] == [
        f"forward simulation vs engine ({T_SHORT} s, passive)",
        "energy drift of the simulation",
    ]
    assert all(c.passed for c in checks), [(c.quantity, c.max_error, c.detail) for c in checks]
    moved = float(checks[0].detail.rsplit("motion of ", 1)[1])
    assert moved > MIN_MOTION
