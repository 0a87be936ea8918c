"""The package's layers import one way, and the table-reading layers load neither numba nor torch.

Layers, ground floor first (docs/architecture.md#layout): config <- physics <- sensors <- env
<- rl <- rollout <- analysis <- claims <- figures <- bench, cli, run_plan, watch. A module may import its
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
    "__init__": 0, "_version": 0, "_numba_cache": 0, "_jit": 0, "io": 0, "config": 0, "layout": 0, "units": 0,
    "drawing": 0, "senses": 0,
    "physics": 1, "sensors": 2, "env": 3, "rl": 4, "rollout": 5, "analysis": 6, "claims": 7, "figures": 8,
    "bench": 9, "cli": 9, "compare_runs": 9, "cli_claims": 9, "cli_support": 9, "progress": 9, "run_plan": 9, "share": 9, "sweep": 9,
    "watch": 9,
    "__main__": 10,
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


#: The config composer: what the layers that read a run's tables must not use (issue 26: the run is the contract).
COMPOSER_MODULE = "efish.config.compose"
COMPOSER_NAMES = {"compose", "compose_variants"}


def composer_uses(name: str, source: str, package: bool = False) -> list[str]:
    """Where module ``name`` (``source``; ``package``: an ``__init__``) imports the config composer
    (efish.config.compose, or compose / compose_variants from efish.config) or calls a function named compose or
    compose_variants, as ``line: what``."""
    here = name if package else name.rsplit(".", 1)[0]
    found = []
    for node in ast.walk(ast.parse(source)):
        if isinstance(node, ast.Import):
            found += [f"{node.lineno}: import {a.name}" for a in node.names if a.name == COMPOSER_MODULE]
        elif isinstance(node, ast.ImportFrom):
            parts = here.split(".")
            base = ".".join(parts[: len(parts) - node.level + 1] + ([node.module] if node.module else [])) \
                if node.level else node.module or ""
            names = {a.name for a in node.names}
            if base == COMPOSER_MODULE or (base == "efish.config" and names & COMPOSER_NAMES):
                found.append(f"{node.lineno}: from {base} import {', '.join(sorted(names))}")
        elif isinstance(node, ast.Call):
            func = node.func
            called = func.id if isinstance(func, ast.Name) else func.attr if isinstance(func, ast.Attribute) else ""
            if called in COMPOSER_NAMES:
                found.append(f"{node.lineno}: calls {called}")
    return found


@pytest.mark.parametrize("layer", ["figures", "claims", "analysis"])
def test_table_readers_never_compose_a_config(layer):
    """Panels, clips and analyses read the conditions the run recorded (conditions.parquet, efish.config.recorded),
    never a config composed afresh without the run's overrides."""
    uses = {module_name(p): u for p in sorted((PACKAGE / layer).rglob("*.py"))
            if (u := composer_uses(module_name(p), p.read_text(), p.name == "__init__.py"))}
    assert not uses, f"efish.{layer} composes configs: {uses}"


@pytest.mark.parametrize("source", ["from ..config import compose\n", "from ..config.compose import config_dir\n",
                                    "from efish.config import compose_variants\n", "import efish.config.compose\n",
                                    "def f(config):\n    return config.compose(['a'])\n"])
def test_the_composer_check_sees_every_way_in(source):
    assert composer_uses("efish.figures.fig9", source)


def test_the_composer_check_lets_the_recorded_configs_through():
    assert not composer_uses("efish.figures.fig9", "from ..config.recorded import recorded_conditions\n"
                                                   "from ..config.schema import EfishConfig\nfrom .. import layout\n")


def test_every_top_level_module_has_a_layer():
    tops = {p.stem if p.is_file() else p.name for p in PACKAGE.iterdir()
            if (p.suffix == ".py") or (p.is_dir() and (p / "__init__.py").exists())}
    assert tops <= set(LAYERS), sorted(tops - set(LAYERS))


@pytest.mark.parametrize("modules", [
    ["efish"],
    ["efish.figures.registry", "efish.figures.render", "efish.figures.gallery"],
    ["efish.analysis." + p.stem for p in sorted((PACKAGE / "analysis").glob("*.py")) if p.stem != "__init__"],
    ["efish.claims." + p.stem for p in sorted((PACKAGE / "claims").glob("*.py")) if p.stem != "__init__"],
    ["efish.config", "efish.rollout.schema"],
    ["efish.watch", "efish.progress"],  # runs beside the jobs it watches (a cluster's login node): it reads tables
], ids=["efish", "figures", "analysis", "claims", "config+schema", "watch"])
def test_table_readers_load_neither_numba_nor_torch(modules):
    code = (f"import importlib, sys\nfor m in {modules!r}: importlib.import_module(m)\n"
            "print(sorted(k for k in ('numba', 'torch') if k in sys.modules))")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120)
    assert out.returncode == 0, out.stderr[-2000:]
    assert out.stdout.strip() == "[]", f"{modules} loaded {out.stdout.strip()}"


def test_python_dash_m_efish_is_the_efish_command():
    out = subprocess.run([sys.executable, "-m", "efish", "--help"], capture_output=True, text=True, timeout=120)
    assert out.returncode == 0 and out.stdout.startswith("usage: efish"), out.stderr[-1000:]
