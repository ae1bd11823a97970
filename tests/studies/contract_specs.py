"""Bad-input specs of robomech.studies (the report layer)."""

import tempfile
from pathlib import Path

from contract_spec import Exempt, Spec, exempt

from robomech import studies

P = "robomech.studies."
DATA = Exempt("report record type: a plain container the studies fill and the writer formats")
RESULT = studies.StudyResult(name="demo", title="Demo", source="contract suite", summary="ok")
_HERE = "<a fresh temporary folder>"  # replaced by a temporary folder at call time


def _in_tmp(fn, key):
    def call(**kw):
        if kw.get(key) == _HERE:
            with tempfile.TemporaryDirectory() as d:
                return fn(**{**kw, key: Path(d)})
        return fn(**kw)

    return call


SPECS = {
    **exempt("Figure Study StudyResult Table", DATA, P),
    P + "Progress": Exempt("progress of study runs (stderr lines, a bar on a terminal), no numeric input"),
    P + "available_studies": Spec(args={}),
    P + "get_study": Spec(args={"name": "demo"}, options={"name": ("no-such-study", None, 1)}),
    P + "comparison_table": Spec(
        args={"title": "t", "rows": [("a", 1.0, 1.1, "m"), ("b", None, 2.0, "s")], "note": ""},
        options={
            "title": (None, 1),
            "rows": (None, "abc", [("a", 1.0)], [("a", "one", 1.1, "m")], [("a", 1.0, None, "m")]),
        },
    ),
    P + "write_study_report": Spec(
        args={"result": RESULT, "out_dir": _HERE, "seconds": 1.5},
        params=("result",),
        options={"out_dir": (None, "", 1), "seconds": (float("nan"), -1.0, "1", True)},
        call=_in_tmp(studies.write_study_report, "out_dir"),
        finite_result=False,
    ),
    P + "write_index": Spec(
        args={"out_root": _HERE, "studies": None, "skipped": [("omnileg", "install robomech[verify]")]},
        options={
            "out_root": (None, "", 1, "/no/such/folder/robomech"),
            "studies": ("abc", {"demo": None}, [1]),
            "skipped": (None, "abc", [("a",)], [(1, "r")], [["a", "b"]]),
        },
        call=_in_tmp(studies.write_index, "out_root"),
    ),
}
