"""The store of verification results a study also shows (robomech.verify._store)."""

from __future__ import annotations

import numpy as np
import pytest

from robomech.mechanisms import vectored_thrust as vt
from robomech.verify import Check, Tolerance, _store
from robomech.verify._store import (
    RESULTS_FOLDER,
    checks_from_arrays,
    checks_to_arrays,
    computed_once,
    reading,
    recording,
    result_key,
)

TH = vt.VectoredThruster.paper()


class Counter:
    """A computation that counts its calls and returns a new value each time."""

    def __init__(self) -> None:
        self.calls = 0

    def __call__(self) -> dict:
        self.calls += 1
        return {"x": np.arange(3.0) * self.calls, "err": 0.5 * self.calls, "ok": True, "text": "é ü"}


def test_reading_returns_what_recording_computed(tmp_path):
    f = Counter()
    with recording(tmp_path):
        first = computed_once("demo", (TH, 2.0), f)
    assert [p.name for p in (tmp_path / RESULTS_FOLDER).iterdir()] == ["demo.npz"]  # no temporary left
    with reading(tmp_path):
        again = computed_once("demo", (TH, 2.0), f)
    assert f.calls == 1
    np.testing.assert_array_equal(again["x"], first["x"])
    # scalars come back as the Python scalars computed, bit for bit
    assert again["err"] == first["err"] and type(again["err"]) is float
    assert again["ok"] is True and again["text"] == "é ü"


def test_missing_or_stale_results_are_computed_and_nothing_is_written_when_reading(tmp_path, monkeypatch):
    f = Counter()
    with reading(tmp_path):  # nothing stored
        assert computed_once("demo", (TH,), f)["err"] == 0.5
    assert f.calls == 1 and not (tmp_path / RESULTS_FOLDER).exists()
    with recording(tmp_path):
        computed_once("demo", (TH,), f)  # calls == 2
    other = vt.VectoredThruster(propeller_arm=TH.propeller_arm * (1 + 1e-15))  # other parameters
    with reading(tmp_path):
        assert computed_once("demo", (other,), f)["err"] == 1.5
        assert computed_once("demo", (TH,), f)["err"] == 1.0  # the stored one
    monkeypatch.setattr(_store, "_code_digest", lambda: "other code")
    with reading(tmp_path):  # stored by other code: stale
        assert computed_once("demo", (TH,), f)["err"] == 2.0
    assert f.calls == 4


def test_an_unreadable_file_is_computed_and_outside_a_mode_nothing_is_read_or_written(tmp_path):
    f = Counter()
    (tmp_path / RESULTS_FOLDER).mkdir()
    (tmp_path / RESULTS_FOLDER / "demo.npz").write_bytes(b"not a zip file")
    with reading(tmp_path):
        assert computed_once("demo", (), f)["err"] == 0.5
    with recording(tmp_path):
        computed_once("demo", (), f)
    assert computed_once("demo", (), f)["err"] == 1.5  # no mode: computed
    assert f.calls == 3


def test_keys_tell_parameters_apart():
    a = np.array([1.0, 2.0])
    assert result_key("r", (a,)) == result_key("r", (a.copy(),))
    assert result_key("r", (a,)) != result_key("r", (a.astype(np.float32),))
    assert result_key("r", (a,)) != result_key("r", (np.array([1.0, 2.0 + 1e-15]),))
    assert result_key("r", (1.0,)) != result_key("r", (1,))
    assert result_key("r", {"a": 1}) != result_key("s", {"a": 1})


def test_checks_round_trip_through_columns():
    checks = [
        Check("m", "q (rel)", 1.2345678901234567e-15, Tolerance(1e-9, "rounding", relative=True), "n = 3"),
        Check("m", "p", float("inf"), Tolerance(2.0, "why")),
        Check("m", "closure", 0.0, Tolerance(1e-9, "why"), "", "n/a", "0 by construction"),
        Check("m", "fall", 1e-7, Tolerance(1e-3, "why"), "d", "inconclusive", "crossed early"),
    ]
    assert checks_from_arrays(checks_to_arrays(checks)) == checks
    assert checks_from_arrays(checks_to_arrays([])) == []
    older = {k: v for k, v in checks_to_arrays(checks[:2]).items() if k not in ("verdict", "note")}
    assert checks_from_arrays(older) == checks[:2]  # a store written before verdicts reads as judged


def test_a_check_states_its_verdict():
    """n/a and inconclusive are neither passed nor failed; anything else is refused."""
    tol = Tolerance(1e-9, "why")
    assert [Check("m", "q", 0.0, tol, verdict=v).status for v in ("", "n/a", "inconclusive")] == [
        "pass",
        "n/a",
        "inconclusive",
    ]
    assert Check("m", "q", 1.0, tol).failed and not Check("m", "q", 1.0, tol, verdict="n/a").failed
    with pytest.raises(ValueError, match="verdict"):
        Check("m", "q", 0.0, tol, verdict="skipped")


def test_bad_input_is_refused():
    with pytest.raises(ValueError, match="name"):
        result_key("a/b", ())
    with pytest.raises(ValueError, match="parameters"):
        result_key("a", (object(),))
    with pytest.raises(ValueError, match="out_root"):
        with reading(3):  # type: ignore[arg-type]
            pass
    with pytest.raises(ValueError, match="compute"):
        computed_once("a", (), lambda: [1.0])  # type: ignore[arg-type,return-value]
