"""The package's layers import one way, and the table-reading layers load neither numba nor torch.

Layers, ground floor first (DESIGN "Layout"): config <- physics <- sensors <- env
<- rl <- rollout <- analysis <- figures <- bench, cli. A module may import its
own layer and the layers below, never one above (imports inside functions
count too: a lazy import is still a dependency).
"""

from __future__ import annotations

import ast
import subprocess
import sys
from pathlib import Path

import pytest

import efish

PACKAGE = Path(efish.__file__).resolve().parent
LAYERS = {
    "__init__": 0, "_version": 0, "_numba_cache": 0, "_jit": 0, "io": 0, "config": 0,
    "physics": 1, "sensors": 2, "env": 3, "rl": 4, "rollout": 5, "analysis": 6, "figures": 7,
    "bench": 8, "cli": 8, "__main__": 9,
}


def layer_of(module: str) -> int:
    """Layer of ``efish.<top>...``: its first component below the package."""
    parts = module.split(".")
    return LAYERS[parts[1] if len(parts) > 1 else "__init__"]


def module_name(path: Path) -> str:
    rel = path.relative_to(PACKAGE.parent).with_suffix("")
    parts = list(rel.parts)
    return ".".join(parts[:-1] if parts[-1] == "__init__" else parts)


def imported_modules(path: Path) -> set[str]:
    """Every efish module ``path`` imports, absolute or relative, anywhere in the file."""
    name = module_name(path)
    package = name if path.name == "__init__.py" else name.rsplit(".", 1)[0]
    found = set()
    for node in ast.walk(ast.parse(path.read_text())):
        if isinstance(node, ast.Import):
            found |= {a.name for a in node.names if a.name.split(".")[0] == "efish"}
        elif isinstance(node, ast.ImportFrom):
            if node.level:
                base = package.split(".")[: len(package.split(".")) - node.level + 1]
                target = ".".join(base + ([node.module] if node.module else []))
            else:
                target = node.module or ""
            if target.split(".")[0] == "efish":
                # ``from . import x`` names a submodule: resolve to it when it is one
                subs = [f"{target}.{a.name}" for a in node.names if (PACKAGE.parent / f"{target}.{a.name}".replace(
                    ".", "/")).with_suffix(".py").exists() or (PACKAGE.parent / f"{target}.{a.name}".replace(".", "/")).is_dir()]
                found |= set(subs) if subs and len(subs) == len(node.names) else {target}
    return found


def test_no_module_imports_a_layer_above_its_own():
    upward = []
    for path in sorted(PACKAGE.rglob("*.py")):
        here = module_name(path)
        for target in imported_modules(path):
            if target != "efish" and layer_of(target) > layer_of(here):
                upward.append(f"{here} -> {target}")
    assert not upward, "imports from a lower layer to a higher one:\n" + "\n".join(upward)


def test_every_top_level_module_has_a_layer():
    tops = {p.stem if p.is_file() else p.name for p in PACKAGE.iterdir()
            if (p.suffix == ".py") or (p.is_dir() and (p / "__init__.py").exists())}
    assert tops <= set(LAYERS), sorted(tops - set(LAYERS))


@pytest.mark.parametrize("modules", [
    ["efish"],
    ["efish.figures.registry", "efish.figures.render"],
    ["efish.analysis." + p.stem for p in sorted((PACKAGE / "analysis").glob("*.py")) if p.stem != "__init__"],
    ["efish.config", "efish.rollout.schema"],
], ids=["efish", "figures", "analysis", "config+schema"])
def test_table_readers_load_neither_numba_nor_torch(modules):
    code = (f"import importlib, sys\nfor m in {modules!r}: importlib.import_module(m)\n"
            "print(sorted(k for k in ('numba', 'torch') if k in sys.modules))")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120)
    assert out.returncode == 0, out.stderr[-2000:]
    assert out.stdout.strip() == "[]", f"{modules} loaded {out.stdout.strip()}"


def test_python_dash_m_efish_is_the_efish_command():
    out = subprocess.run([sys.executable, "-m", "efish", "--help"], capture_output=True, text=True, timeout=120)
    assert out.returncode == 0 and out.stdout.startswith("usage: efish"), out.stderr[-1000:]
