"""The compile step: a frozen description compiles once, outside itself, with no import circle."""

from __future__ import annotations

import ast
import gc
import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from robomech import multibody as mb
from robomech.multibody import _compile

PKG = Path(mb.__file__).resolve().parent
SRC = PKG.parents[1]
# A fresh interpreter compiling one kernel with empty caches: ~10-30 s on the shared machine.
SUBPROCESS_TIMEOUT = 300


def test_compile_once_and_never_into_the_description():
    mech = mb.gallery.load("delta")
    fields = set(mech.__dict__)
    model = _compile.compile_model(mech)
    assert _compile.compile_model(mech) is model
    fk = mb.forward_kinematics(mech, mech.q0[mech.tree.act_qadr][None] + 0.01)
    mb.site_jacobian(mech, fk.q, mech.sites[0].name)
    mb.inverse_dynamics(mech, fk.q, np.ones((1, 3)), np.zeros((1, 3)))
    mb.singularities(mech, fk.q, mech.sites[0].name)
    assert set(mech.__dict__) == fields  # nothing written into the frozen description
    assert model.tree is mech.tree and model.constraints is mech.constraints
    assert (model.dof, model.rank0) == (3, len(model.pas) - model.idle_dof)


def test_compiled_model_is_released_with_its_description():
    mech = mb.gallery.load("four_bar")
    key = id(mech)
    _compile.compile_model(mech)
    assert key in _compile._MODELS
    del mech
    gc.collect()
    assert key not in _compile._MODELS


def _module_imports(path: Path) -> set[str]:
    """Sibling modules imported at module level (``from . import x`` / ``from ._x import y``)."""
    out = set()
    for node in ast.parse(path.read_text()).body:
        if isinstance(node, ast.ImportFrom) and node.level == 1:
            if node.module:
                out.add(node.module)
            else:
                out.update(a.name for a in node.names)
    return out


def test_no_import_circle_in_the_layer():
    graph = {p.stem: _module_imports(p) for p in PKG.glob("*.py")}
    seen: dict[str, int] = {}  # 1 on the stack, 2 done

    def visit(m: str, path: list[str]) -> None:
        if seen.get(m) == 1:
            pytest.fail(f"import circle: {' -> '.join([*path, m])}")
        if seen.get(m) == 2 or m not in graph:
            return
        seen[m] = 1
        for n in graph[m]:
            visit(n, [*path, m])
        seen[m] = 2

    for m in graph:
        visit(m, [])
    # control: the check sees a circle when there is one
    graph["_tree"] = graph["_tree"] | {"_compile"}
    seen.clear()
    with pytest.raises(pytest.fail.Exception, match="import circle"):
        for m in graph:
            visit(m, [])


def _nb_files() -> set[Path]:
    return {p for p in SRC.rglob("*") if p.suffix in (".nbc", ".nbi")}


@pytest.mark.slow
def test_kernels_cache_outside_the_package_and_say_when_they_compile(tmp_path):
    """A fresh process whose application imported numba first (robomech could not set the
    environment variable in time), with empty caches: the kernels compile into robomech's cache
    directory, never under src/, and every compilation is logged on the "robomech" logger."""
    before = _nb_files()
    code = (
        "import numba, logging, numpy as np\n"  # numba first, as an application may do
        "logging.basicConfig(level=logging.INFO, format='%(name)s %(message)s')\n"
        "from robomech.analysis import lstsq\n"
        "lstsq.solve(np.eye(3)[None], np.ones((1, 3)))\n"
    )
    env = {**os.environ, "XDG_CACHE_HOME": str(tmp_path), "PYTHONPATH": str(SRC)}
    env.pop("NUMBA_CACHE_DIR", None)
    out = subprocess.run(
        [sys.executable, "-c", code], env=env, capture_output=True, text=True, timeout=SUBPROCESS_TIMEOUT
    )
    assert out.returncode == 0, out.stderr
    assert "robomech compiling kernel" in out.stderr and str(tmp_path / "robomech" / "numba") in out.stderr
    assert "robomech compiled kernel" in out.stderr
    assert _nb_files() == before, sorted(map(str, _nb_files() - before))
    assert any(p.suffix == ".nbi" for p in (tmp_path / "robomech" / "numba").rglob("*"))


@pytest.mark.slow
def test_a_plain_script_is_told_once_that_kernels_compile(tmp_path):
    """Without any logging configuration (a plain script), the first compilation of a process is a
    warning Python prints on its own, once; the kernels' own lines stay at INFO."""
    code = (
        "import numpy as np\n"
        "from robomech.analysis import lstsq\n"
        "lstsq.solve(np.eye(3)[None], np.ones((1, 3)))\n"
    )
    env = {**os.environ, "XDG_CACHE_HOME": str(tmp_path), "PYTHONPATH": str(SRC)}
    env.pop("NUMBA_CACHE_DIR", None)
    run = [sys.executable, "-c", code]
    out = subprocess.run(run, env=env, capture_output=True, text=True, timeout=SUBPROCESS_TIMEOUT)
    assert out.returncode == 0, out.stderr
    assert out.stderr.count("compiling robomech's kernels") == 1, out.stderr
    assert "compiling kernel" not in out.stderr  # the per-kernel lines are INFO
    again = subprocess.run(run, env=env, capture_output=True, text=True, timeout=SUBPROCESS_TIMEOUT)
    assert again.returncode == 0 and "compiling" not in again.stderr, again.stderr  # cached: silent
