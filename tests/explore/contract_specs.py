"""Bad-input specs of robomech.explore (design studies, sampling, sweeps on Dask, Zarr stores).

``run_sweep`` and ``optimize_nsga2`` validate every argument before they start a cluster or touch the
store; their one good call each starts a one-worker LocalCluster (``slow``).
"""

import atexit
import dataclasses
import shutil
import tempfile
from pathlib import Path

import numpy as np
from contract_spec import (
    BAD_BOOL,
    BAD_POSITIVE,
    BAD_STR,
    CONSTANT,
    RESULT_TYPE,
    Exempt,
    Spec,
)

from robomech.explore import Objective, Variable, design_matrix, get_study, load_model
from robomech.explore._runner import sweep_fingerprint
from robomech.explore._store import prepare_store

P = "robomech.explore."
_FIVE_BAR = Path(__file__).resolve().parents[2] / "examples" / "models" / "five_bar.py"


def _metric_fn(mech, params):
    return 0.0


_five_bar = load_model(f"{_FIVE_BAR}:build")

STUDY = get_study("spherical-leg-synthesis")
VARS = STUDY.variables
TMP = Path(tempfile.mkdtemp(prefix="robomech-contract-explore-"))
atexit.register(shutil.rmtree, TMP, True)

# a valid (empty) store for open_results, written without a cluster
_X = design_matrix(VARS, 4, "sobol", 0, 2)
prepare_store(TMP / "store", STUDY, _X, 2, sweep_fingerprint(STUDY, 4, "sobol", 0, 2), STUDY.describe())
(TMP / "file.txt").write_text("not a store")
_TEMPLATE = TMP / "pendulum.xml"
_TEMPLATE.write_text(
    '<mujoco><worldbody><body name="b"><joint name="j" type="hinge" axis="0 1 0"/>'
    '<geom type="capsule" fromto="0 0 0 {L} 0 0" size="0.01"/><site name="tip" pos="{L} 0 0"/>'
    '</body></worldbody><actuator><motor joint="j"/></actuator></mujoco>'
)

# integer options whose default is None (None is valid there)
BAD_COUNT = ("1", True, 1.5, float("nan"), 1j, 0, -1)
BAD_SEED = (None, "1", True, 1.5, float("nan"), 1j, -1)
BAD_VARIABLES = (None, "R", (1,), [Variable("L9", 0.1, 0.2)])
METRICS = {"a": np.array([0.1, 0.5, 0.3]), "b": np.array([1.0, 2.0, 0.5]), "design_ok": np.ones(3, bool)}
OBJECTIVES = (Objective("a", "max"), Objective("b", "min"))
_FIELDS = {f.name: getattr(STUDY, f.name) for f in dataclasses.fields(STUDY)}
_RUNTIME = {
    "scheduler": ("127.0.0.1:8786", 1),
    "workers": BAD_COUNT,
    "progress": BAD_BOOL,
    "connect_timeout": BAD_POSITIVE,
    "out": (None, 1, ""),
    "variables": BAD_VARIABLES,
    "seed": BAD_SEED,
}


def _cluster_started_and_closed(workers):
    """local_cluster's good call: start the cluster, count its workers, stop every process it started."""
    from robomech.explore import local_cluster

    with local_cluster(workers) as cluster:
        return len(cluster.workers)


SPECS = {
    P + "SAMPLERS": CONSTANT,
    P + "SweepSummary": RESULT_TYPE,
    P + "StoreMismatch": Exempt("exception type: raised by the library, takes no input to validate"),
    P + "SchedulerUnreachable": Exempt("exception type: raised by the library, takes no input to validate"),
    P + "StoreDamaged": Exempt("exception type: raised by the library, takes no input to validate"),
    P + "GENERIC_METRICS": Exempt("constant: the generic metrics' units, definitions and requirements"),
    P + "ModelStudy": Exempt("made by model_study, which validates every field; a DesignStudy subclass"),
    P + "UserMetric": Spec(
        args={"name": "m", "fn": _metric_fn, "unit": "m", "description": "d"},
        options={"name": (None, 1, "not an id", "task_fraction"), "fn": (None, 1), "unit": (None, 1)},
    ),
    P + "load_model": Spec(
        args={"spec": f"{_FIVE_BAR}:build"},
        options={"spec": (None, 1, "", str(TMP / "missing.py:build"), f"{_FIVE_BAR}:nope")},
    ),
    P + "template_builder": Spec(
        args={"path": str(_TEMPLATE)},
        options={"path": (None, 1, "", str(TMP / "missing.xml"), str(TMP / "file.txt"))},
    ),
    P + "model_study": Spec(
        args={
            "build": _five_bar,
            "variables": (Variable("L1", 0.15, 0.25),),
            "site": "tip",
            "metrics": ("workspace_measure",),
            "outputs": "xy",
            "task_box": [[-0.5, 0.5], [-0.5, 0.5]],
            "task_grid_size": 4,
        },
        options={
            "build": (None, 1),
            "variables": (None, (), (Variable("nope", 0, 1),), (Variable("e", kind="normal", sigma=1.0),)),
            "site": (None, "", 1),
            "metrics": (None, "workspace_measure", ("nope",), ()),
            "outputs": (None, "yx", "q", "xx", ""),
            "task_box": ([[0, 1]], [[1, 0], [0, 1]], "a", [[np.nan, 1], [0, 1]]),
            "task_grid_size": (None, 1, 1.5, 10**5),
        },
    ),
    P + "available_studies": Exempt("registry: takes no input"),
    P + "Variable": Spec(
        args={"name": "R", "low": 0.05, "high": 0.1, "unit": "m", "kind": "range", "description": ""},
        options={
            "name": (*BAD_STR, "not an identifier"),
            "low": (float("nan"), float("inf"), -float("inf"), None, "1.0", True, 1j, [1.0, 2.0], 0.2),
            "high": (float("nan"), float("inf"), None, "1.0", True, 1j, [1.0, 2.0], 0.05),
            "unit": (None, 1),
            "kind": ("uniform", None, 1),
            "description": (None, 1),
        },
    ),
    P + "Metric": Spec(
        args={"name": "m", "unit": "1", "description": "d", "shape": (3,), "dtype": "float64"},
        options={
            "name": BAD_STR,
            "unit": (None, 1),
            "description": (None, 1),
            "shape": (None, 3, (0,), (1.5,), ("3",)),
            "dtype": ("int8", None, 1),
        },
    ),
    P + "Objective": Spec(
        args={"metric": "a", "sense": "max"},
        options={"metric": (None, 1), "sense": ("up", None, 1)},
    ),
    P + "DesignStudy": Spec(
        args=_FIELDS,
        options={
            "name": (None, 1),
            "nominal": (None, 1),
            "evaluate": (None, "f"),
            "variables": (None, (), ("R",), [VARS[0]]),
            "metrics": (None, (), (1,)),
            "objectives": (None, (Objective("nope", "max"),)),
            "poses_per_design": (None, 0, 1.5, True),
            "default_chunk": (None, 0, "1", True),
            "default_designs": (None, 0, 2.5),
            "default_sampler": ("halton", None),
            "parameters": (None, [1]),
        },
    ),
    P + "chunk_seed": Spec(args={"seed": 0, "chunk": 3}, options={"seed": BAD_SEED, "chunk": BAD_SEED}),
    P + "design_matrix": Spec(
        args={"variables": VARS, "n": 8, "sampler": "sobol", "seed": 0, "chunk": 4},
        options={
            "variables": (None, "R", (1,), ()),
            "n": (None, "8", True, 1.5, 0, -1),
            "sampler": ("halton", None, 1),
            "seed": BAD_SEED,
            "chunk": (None, "4", True, 0),
        },
    ),
    P + "local_cluster": Spec(
        args={"workers": 1}, options={"workers": BAD_COUNT}, call=_cluster_started_and_closed, slow=True
    ),
    P + "get_study": Spec(args={"name": "omnileg-synthesis"}, options={"name": ("no-such-study", None, 1)}),
    P + "with_variables": Spec(
        args={"study": STUDY, "variables": (Variable("R", 0.06, 0.09),)},
        params=("study",),
        options={"variables": BAD_VARIABLES},
    ),
    P + "pareto_front": Spec(
        args={"metrics": METRICS, "objectives": OBJECTIVES},
        options={
            "metrics": (None, [1.0], {"a": np.ones(3)}, {"a": "x", "b": np.ones(3)}),
            "objectives": (None, (), "a", (1,)),
        },
    ),
    P + "open_results": Spec(
        args={"out": str(TMP / "store")},
        options={"out": (None, 1, "", str(TMP / "missing"), str(TMP / "file.txt"), str(TMP))},
    ),
    P + "run_sweep": Spec(
        args={
            "study": STUDY,
            "out": str(TMP / "run"),
            "designs": 2,
            "chunk_size": 2,
            "seed": 0,
            "sampler": "sobol",
            "variables": (),
            "scheduler": None,
            "workers": 1,
            "progress": False,
            "connect_timeout": 5.0,
        },
        params=("study",),
        options={**_RUNTIME, "designs": BAD_COUNT, "chunk_size": BAD_COUNT, "sampler": ("halton", 1)},
        slow=True,
    ),
    P + "optimize_nsga2": Spec(
        args={
            "study": STUDY,
            "out": str(TMP / "nsga2"),
            "population": 4,
            "generations": 1,
            "seed": 0,
            "variables": (),
            "scheduler": None,
            "workers": 1,
            "progress": False,
            "connect_timeout": 5.0,
        },
        params=("study",),
        options={**_RUNTIME, "population": (*BAD_COUNT, 3), "generations": (None, *BAD_COUNT)},
        slow=True,
    ),
}
