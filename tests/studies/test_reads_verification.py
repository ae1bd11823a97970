"""Studies read the results `robomech verify --out` stored instead of computing them again, and compute
them by the verification's own function when they are missing or stale (robomech.verify._store).

The engine computations are replaced by stand-ins that count their calls: what is tested is which
call site runs, not the engine (tests/verify checks that)."""

from __future__ import annotations

import dataclasses
from types import SimpleNamespace

import numpy as np
import pytest

from robomech.mechanisms import continuum as C
from robomech.mechanisms import vectored_thrust as vt
from robomech.studies import Progress
from robomech.verify import Check, Tolerance, _store
from robomech.verify._store import reading, recording

pytest.importorskip("mujoco")


def _fails(*args, **kwargs):
    raise AssertionError("recomputed although the verification's result is stored")


def test_vectored_thrust_study_reads_the_verification_checks(tmp_path, monkeypatch):
    from robomech.studies import vectored_thrust as study
    from robomech.verify import vectored_thrust as vv

    stored = [Check("vectored-thrust", "stand-in", 1.25e-9, Tolerance(1e-6, "test"))]
    monkeypatch.setattr(vv, "_checks", lambda *a: stored)
    with recording(tmp_path):
        vv.VERIFICATION.run()  # what `robomech verify --out` calls
    monkeypatch.setattr(vv, "_checks", _fails)
    with reading(tmp_path):
        assert study.verification(vt.VectoredThruster.paper()) == stored


def test_vectored_thrust_study_computes_missing_or_stale_checks(tmp_path, monkeypatch):
    from robomech.studies import vectored_thrust as study
    from robomech.verify import vectored_thrust as vv

    fresh = [Check("vectored-thrust", "fresh", 0.0, Tolerance(1e-6, "test"))]
    monkeypatch.setattr(vv, "_checks", lambda *a: fresh)
    with reading(tmp_path):  # missing
        assert study.verification(vt.VectoredThruster.paper()) == fresh
    with monkeypatch.context() as m:  # recorded by other code: stale
        m.setattr(_store, "_code_digest", lambda: "other code")
        m.setattr(vv, "_checks", lambda *a: [])
        with recording(tmp_path):
            vv.VERIFICATION.run()
    with reading(tmp_path):
        assert study.verification(vt.VectoredThruster.paper()) == fresh


def _stand_in_simulation(leg, em, duration):
    t = np.linspace(0.0, duration, 5)
    q = np.outer(t, [1.0, 2.0, 3.0])
    return {"t": t, "q_sim": q + 1e-5, "q_ref": q, "drift": 1e-5, "closure": 2e-7}


def test_omnileg_study_reads_the_verification_simulation(tmp_path, monkeypatch):
    from robomech.studies import omnileg as study
    from robomech.verify import omnileg as vo

    monkeypatch.setattr(vo, "_simulate", _stand_in_simulation)
    with recording(tmp_path):
        checks = vo.VERIFICATION.run()  # the checks before the simulation leave the engine model as built
    assert [c.max_error for c in checks[-2:]] == [1e-5, 2e-7]
    monkeypatch.setattr(vo, "_simulate", _fails)
    with reading(tmp_path):
        sim = study.engine_fig11(study.ol.OmniLeg.paper()).simulation
    expected = _stand_in_simulation(None, None, 2.0)
    assert sim.keys() == expected.keys()
    for k, v in expected.items():
        np.testing.assert_array_equal(sim[k], v)


def test_omnileg_study_computes_a_stale_simulation(tmp_path, monkeypatch):
    from robomech.studies import omnileg as study
    from robomech.verify import omnileg as vo

    leg = study.ol.OmniLeg.paper()
    with monkeypatch.context() as m:  # another leg: another key
        m.setattr(vo, "_simulate", lambda *a: {"drift": -1.0})
        with recording(tmp_path):
            vo.forward_simulation(dataclasses.replace(leg, L1=0.16), vo.build_model(leg))
    monkeypatch.setattr(vo, "_simulate", _stand_in_simulation)
    with reading(tmp_path):
        assert study.engine_fig11(leg).simulation["drift"] == 1e-5


class _CountingSolver:
    """Stands in for the disk-resolved solve: tip error = the call's number (mm) along x."""

    def __init__(self) -> None:
        self.drives: list[np.ndarray] = []

    def __call__(self, robot, *, drive, direction):
        self.drives.append(drive)
        T = np.eye(4)[None].copy()
        T[0, 0, 3] = 1e-3 * len(self.drives)
        return SimpleNamespace(T_tip=T, converged=np.array([True]), taut=np.array([True]))


def test_continuum_study_reads_the_verification_compensation_solves(tmp_path, monkeypatch):
    from robomech.studies import continuum as study
    from robomech.verify import continuum as V

    robot = C.ContinuumRobot.paper()
    solver = _CountingSolver()
    monkeypatch.setattr(V, "solve_disk_robot", solver)
    with recording(tmp_path):  # the two solves of the verification's compensation check
        recorded = {k: V.compensation_on_reference(robot, 90.0, k) for k in ("chord", "disk")}
    assert len(solver.drives) == 2
    with reading(tmp_path):
        _, data = study.reference_compensation(Progress(enabled=False))
    # 2 bends x 3 drives, of which the verification's two were read: 4 solves more
    assert len(solver.drives) == 2 + 4
    assert data["90"][0] == recorded["chord"]["tip_error"] and data["90"][2] == recorded["disk"]["tip_error"]
    with reading(tmp_path / "elsewhere"):  # nothing stored: all six solved
        study.reference_compensation(Progress(enabled=False))
    assert len(solver.drives) == 6 + 6
