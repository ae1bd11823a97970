"""The layering of docs/architecture.md, enforced by parsing every module's imports."""

import ast
import subprocess
import sys
from pathlib import Path

SRC = Path(__file__).resolve().parents[1] / "src" / "robomech"

# layer -> robomech layers it may import (besides itself and the infrastructure modules
# robomech._validation, robomech._registry, robomech._numba)
ALLOWED = {
    "spatial": set(),
    "kinematics": {"spatial"},
    "trajectory": set(),
    "testing": {"spatial"},
    "dynamics": {"spatial", "kinematics"},
    "analysis": {"spatial", "kinematics"},
    "multibody": {"spatial", "kinematics", "trajectory", "dynamics", "analysis"},
    # the browser viewer: a consumer of multibody only (viser lazily, inside functions)
    "viewer": {"spatial", "kinematics", "trajectory", "dynamics", "analysis", "multibody"},
    "mechanisms": {"spatial", "kinematics", "trajectory", "dynamics", "analysis", "multibody"},
    "explore": {"spatial", "kinematics", "trajectory", "dynamics", "analysis", "multibody", "mechanisms"},
    "verify": {
        "spatial",
        "kinematics",
        "trajectory",
        "dynamics",
        "analysis",
        "multibody",
        "mechanisms",
        "explore",
    },
    "studies": {
        "spatial",
        "kinematics",
        "trajectory",
        "dynamics",
        "analysis",
        "multibody",
        "mechanisms",
        "explore",
        "verify",
        "testing",
    },
    "cli": {"studies", "verify", "explore", "viewer"},
    "__main__": {"cli"},  # `python -m robomech`
}
INFRASTRUCTURE = {
    "robomech",
    "robomech._validation",
    "robomech._registry",
    "robomech._numba",
    "robomech._progress",
    "robomech._batching",
}
ENGINES = {"mujoco", "exudyn", "pinocchio"}
# The distributed-computing stack of robomech.explore: imported inside functions only (first use).
LAZY = {"dask", "distributed", "zarr", "pymoo"}
# Deliberate exceptions to the engine / matplotlib rules, each imported lazily inside a function (never
# at module level), so that the rest of the layer and `import robomech.multibody` need neither: reading
# MJCF needs MuJoCo's own compiler (an optional extra), and the wireframe drawing needs matplotlib
# (docs/architecture.md).
LAZY_ONLY = {
    ("multibody", "_mjcf.py"): {"mujoco"},
    ("multibody", "_draw.py"): {"matplotlib"},
    ("multibody", "_animate.py"): {"matplotlib", "PIL"},
    ("multibody", "_repr.py"): {"matplotlib"},
    ("multibody", "_pinocchio.py"): {"pinocchio"},  # the Pinocchio bridge (the pinocchio extra)
    ("viewer", "_server.py"): {"viser", "imageio", "webbrowser"},
    ("viewer", "_geoms.py"): {"mujoco"},  # an MJCF file's geoms, compiled by MuJoCo (the verify extra)
}
# The web stack of the viewer: only robomech.viewer imports it, and only inside functions.
WEB = {"viser"}
# One upward import, inside the one function that needs it: ``multibody.view`` forwards to the viewer
# (``mb.view(mech)``), so that the viewer's layer stays above multibody and ``import robomech.multibody``
# never loads it.
UPWARD_LAZY = {("multibody", "_draw.py"): {"viewer"}}


def _imports(path: Path) -> list[str]:
    tree = ast.parse(path.read_text())
    names = []
    pkg = path.relative_to(SRC.parent).with_suffix("").parts
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            names += [a.name for a in node.names]
        elif isinstance(node, ast.ImportFrom):
            if node.level:
                base = (
                    list(pkg[: len(pkg) - node.level])
                    if path.name != "__init__.py"
                    else list(pkg[: len(pkg) - node.level + 1])
                )
                mod = ".".join(base + ([node.module] if node.module else []))
            else:
                mod = node.module or ""
            names.append(mod)
    return names


def _layer(path: Path) -> str:
    rel = path.relative_to(SRC).parts
    return rel[0].removesuffix(".py")


def test_every_module_respects_the_layering():
    problems = []
    for path in SRC.rglob("*.py"):
        layer = _layer(path)
        if layer in ("__init__", "_validation", "_registry", "_numba"):
            continue
        lazy = LAZY_ONLY.get((layer, path.name), set())
        upward = UPWARD_LAZY.get((layer, path.name), set())
        for mod in _module_level_imports(path):
            if mod.split(".")[0] in lazy:
                problems.append(f"{path.relative_to(SRC)} imports {mod} at module level (lazy only)")
            if mod.startswith("robomech.") and mod.split(".")[1] in upward:
                problems.append(f"{path.relative_to(SRC)} imports {mod} at module level (lazy only)")
        for mod in _imports(path):
            top = mod.split(".")[0]
            if top in ENGINES and layer != "verify" and top not in lazy:
                problems.append(f"{path.relative_to(SRC)} imports engine {mod}")
            if top == "matplotlib" and layer != "studies" and top not in lazy:
                problems.append(f"{path.relative_to(SRC)} imports matplotlib")
            if top in WEB and (layer != "viewer" or top not in lazy):
                problems.append(f"{path.relative_to(SRC)} imports {mod} (only robomech.viewer, lazily)")
            if top != "robomech" or mod in INFRASTRUCTURE:
                continue
            target = mod.split(".")[1]
            if target != layer and target not in ALLOWED[layer] and target not in upward:
                problems.append(f"{path.relative_to(SRC)} ({layer}) imports {mod}")
            if layer == "mechanisms" and target == "mechanisms":
                own = path.relative_to(SRC).parts[1]
                other = mod.split(".")[2] if len(mod.split(".")) > 2 else own
                if other != own:
                    problems.append(f"{path.relative_to(SRC)} imports another mechanism {mod}")
    assert not problems, "\n".join(problems)


def _module_level_imports(path: Path) -> list[str]:
    tree = ast.parse(path.read_text())
    names = []
    for node in tree.body:
        if isinstance(node, ast.Import):
            names += [a.name for a in node.names]
        elif isinstance(node, ast.ImportFrom) and not node.level:
            names.append(node.module or "")
    return names


def test_distributed_stack_is_imported_lazily():
    problems = [
        f"{path.relative_to(SRC)} imports {mod} at module level"
        for path in SRC.rglob("*.py")
        for mod in _module_level_imports(path)
        if mod.split(".")[0] in LAZY
    ]
    assert not problems, "\n".join(problems)


def test_import_robomech_explore_does_not_load_the_distributed_stack():
    code = (
        "import sys, robomech, robomech.explore as e; e.available_studies(); "
        "print(','.join(m for m in ('dask', 'distributed', 'zarr', 'pymoo') if m in sys.modules))"
    )
    out = subprocess.run(
        [sys.executable, "-c", code], capture_output=True, text=True, check=True
    ).stdout.strip()
    assert out == "", f"import robomech.explore pulled in: {out}"


def test_import_robomech_is_light():
    code = (
        "import sys, robomech, robomech.multibody; "
        "heavy = [m for m in ('scipy', 'sympy', 'matplotlib', 'mujoco', 'dask', 'zarr', 'pymoo', "
        "'robomech.explore', 'robomech.viewer', 'viser') if m in sys.modules];"
        "print(','.join(heavy))"
    )
    out = subprocess.run(
        [sys.executable, "-c", code], capture_output=True, text=True, check=True
    ).stdout.strip()
    assert out == "", f"import robomech pulled in: {out}"
