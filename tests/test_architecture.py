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
    "mechanisms": {"spatial", "kinematics", "trajectory", "dynamics", "analysis"},
    "verify": {"spatial", "kinematics", "trajectory", "dynamics", "analysis", "mechanisms"},
    "studies": {
        "spatial",
        "kinematics",
        "trajectory",
        "dynamics",
        "analysis",
        "mechanisms",
        "verify",
        "testing",
    },
    "cli": {"studies", "verify"},
    "__main__": {"cli"},  # `python -m robomech`
}
INFRASTRUCTURE = {"robomech", "robomech._validation", "robomech._registry", "robomech._numba"}
ENGINES = {"mujoco", "exudyn", "pinocchio"}


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
        for mod in _imports(path):
            top = mod.split(".")[0]
            if top in ENGINES and layer != "verify":
                problems.append(f"{path.relative_to(SRC)} imports engine {mod}")
            if top == "matplotlib" and layer != "studies":
                problems.append(f"{path.relative_to(SRC)} imports matplotlib")
            if top != "robomech" or mod in INFRASTRUCTURE:
                continue
            target = mod.split(".")[1]
            if target != layer and target not in ALLOWED[layer]:
                problems.append(f"{path.relative_to(SRC)} ({layer}) imports {mod}")
            if layer == "mechanisms" and target == "mechanisms":
                own = path.relative_to(SRC).parts[1]
                other = mod.split(".")[2] if len(mod.split(".")) > 2 else own
                if other != own:
                    problems.append(f"{path.relative_to(SRC)} imports another mechanism {mod}")
    assert not problems, "\n".join(problems)


def test_import_robomech_is_light():
    code = (
        "import sys, robomech; "
        "heavy = [m for m in ('scipy', 'sympy', 'matplotlib', 'mujoco') if m in sys.modules];"
        "print(','.join(heavy))"
    )
    out = subprocess.run(
        [sys.executable, "-c", code], capture_output=True, text=True, check=True
    ).stdout.strip()
    assert out == "", f"import robomech pulled in: {out}"
