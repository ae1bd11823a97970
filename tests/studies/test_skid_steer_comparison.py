"""The contact-physics comparison of the skid-steer study, on short runs (the study runs 15 s each)."""

from __future__ import annotations

import numpy as np
import pytest

from robomech.mechanisms.skid_steer import ExplorationRobot
from robomech.studies import _skid_steer_comparison as cmp
from robomech.studies._core import Progress


@pytest.mark.slow
def test_comparison_runs_every_manoeuvre_and_estimator_and_writes_its_figures(tmp_path):
    robot = ExplorationRobot.paper()
    some = tuple(m for m in cmp.MANOEUVRES if m[0] in ("straight, flat", "turn, flat", "turn, uneven"))
    comp = cmp.compare(robot, Progress(enabled=False), duration=1.5, identification_s=1.5, manoeuvres=some)
    assert [r["name"] for r in comp.rows] == ["straight, flat", "turn, flat", "turn, uneven"]
    assert comp.chi > 1.5  # the skid: an effective track width well above the real one
    for r in comp.rows:
        assert set(r["drift_per_m"]) == set(cmp.ESTIMATORS)
        assert all(np.isfinite(v) and v >= 0 for v in r["drift_per_m"].values())
        assert r["on_terrain"]
    turn = next(r for r in comp.rows if r["name"] == "turn, flat")
    assert turn["yaw_rms"][cmp.ESTIMATORS[1]] < 0.3 * turn["yaw_rms"][cmp.ESTIMATORS[0]]  # ICR beats no-slip
    tables = cmp.tables(comp, robot)
    assert len(tables) == 5
    figs = cmp.figures(comp, tmp_path)
    assert len(figs) == 5 and all(f.path.exists() for f in figs)
