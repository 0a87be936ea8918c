"""efish.layout is the one home of a run's paths: it names every file, reads the names back, and no other file of
the package or the workflow writes a results path pattern."""

from __future__ import annotations

import ast
import re
from pathlib import Path

import pytest

import efish
from efish.layout import (
    Run,
    analysis_table,
    assay_table,
    parse_recipe_draw,
    parse_table,
    recipe_draw,
    seed_name,
    stacked_seeds_table,
    training_file,
)

PACKAGE = Path(efish.__file__).resolve().parent
WORKFLOW = PACKAGE.parents[1] / "workflow"
FOLDERS = ("results", "figures", "assays", "analysis", "train", "selection", "seeds", "scenes", "claims", "logs",
           "benchmarks")
PATTERN = re.compile(rf"^({'|'.join(FOLDERS)})/")


def test_names_and_their_parse_agree():
    assert assay_table("patchy4", "steps") == "assays/patchy4/steps.parquet"
    assert parse_table(assay_table("patchy4", "steps")) == ("assays", "patchy4", "", "steps")
    assert parse_table(analysis_table("behaviour", "onepatch", "theil")) == ("analysis", "onepatch", "behaviour",
                                                                             "theil")
    assert parse_table(stacked_seeds_table("wide2")) == ("seeds", "wide2", "", "episodes")
    assert parse_table(training_file(seed_name(3), "metrics.parquet")) is None
    # a policy recipe's draws (scale.homing_seeds): draw 1 is the recipe's own folder
    assert [recipe_draw("homing_raycast", k) for k in (1, 2, "{draw}")] == [
        "homing_raycast", "homing_raycast_draw_2", "homing_raycast_draw_{draw}"]
    for name in ("homing", "homing_draw_2", "homing_raycast_draw_12"):
        assert recipe_draw(*parse_recipe_draw(name)) == name
    assert parse_recipe_draw("homing_draw_1") == ("homing_draw_1", 1)  # draw 1 is never spelt so


def test_a_run_and_its_top_seeds_share_one_layout():
    run = Run("laptop")
    assert run.path(assay_table("wide2", "steps")) == Path("results/laptop/assays/wide2/steps.parquet")
    seed = run.top_seed(4)
    assert seed.path(assay_table("wide2", "steps")) == Path("results/laptop/seeds/seed_4/assays/wide2/steps.parquet")
    # one folder times the whole run: a top seed's logs and benchmarks stay under the run's own
    assert seed.log("assays/wide2") == Path("results/laptop/logs/seeds/seed_4/assays/wide2.log")
    assert seed.benchmark("claims") == Path("results/laptop/benchmarks/seeds/seed_4/claims.tsv")
    assert run.panel("fig3", "K", "png") == Path("figures/laptop/fig3/K.png")
    assert Run("{run}").top_seed("{seed}").path("claims/claims.parquet") == Path(
        "results/{run}/seeds/seed_{seed}/claims/claims.parquet")
    stage = run.stage(2)  # a training stage's copy: the selected seed's stage_2.pt acting
    assert stage.path(assay_table("wide2", "steps")) == Path("results/laptop/learning/stage_2/assays/wide2/steps.parquet")
    assert stage.log("claims") == Path("results/laptop/logs/learning/stage_2/claims.log")
    assert stage.within(None) == run and stage.figures == run.figures


def path_patterns(path: Path) -> list[str]:
    """String literals, f-strings and ``/ "folder"`` joins of ``path`` that build a run's path by hand (docstrings,
    which describe the layout, excepted)."""
    tree = ast.parse(path.read_text())
    docstrings = {id(node.body[0].value) for node in ast.walk(tree)
                  if isinstance(node, (ast.Module, ast.ClassDef, ast.FunctionDef, ast.AsyncFunctionDef))
                  and node.body and isinstance(node.body[0], ast.Expr)
                  and isinstance(node.body[0].value, ast.Constant)}
    found = []
    for node in ast.walk(tree):
        if isinstance(node, ast.Constant) and isinstance(node.value, str) and id(node) not in docstrings:
            if PATTERN.match(node.value):
                found.append(node.value)
        elif isinstance(node, ast.JoinedStr) and node.values and isinstance(node.values[0], ast.Constant):
            if PATTERN.match(str(node.values[0].value)):
                found.append(ast.unparse(node))
        elif isinstance(node, ast.BinOp) and isinstance(node.op, ast.Div) and isinstance(node.right, ast.Constant):
            if node.right.value in FOLDERS:
                found.append(ast.unparse(node))
    return found


@pytest.mark.parametrize("path", sorted(p for p in PACKAGE.rglob("*.py") if p.name != "layout.py"),
                         ids=lambda p: str(p.relative_to(PACKAGE)))
def test_no_module_but_the_layout_writes_a_results_path(path):
    assert path_patterns(path) == []


def test_no_rule_writes_a_results_path():
    for path in [WORKFLOW.parent / "Snakefile", *sorted((WORKFLOW / "rules").glob("*.smk"))]:
        code = [line for line in path.read_text().splitlines() if not line.lstrip().startswith("#")]
        # a results folder or a run's figures folder spelt out (log job names such as "figures/fig3" are not paths)
        hits = [line for line in code if re.search(r"""["'](results/|figures/\{(run|RUN)\})""", line)]
        assert hits == [], path
