"""efish compare-claims over two or more runs: the claims x runs table and its heatmap (efish.claims.grid)."""

from __future__ import annotations

import matplotlib
import numpy as np
import pandas as pd
import pytest
from matplotlib.colors import to_hex

from efish.claims.grid import claims_grid, headline
from efish.cli import main
from efish.figures.claims_grid import heatmap_figure
from efish.figures.learning import VERDICT_COLOURS

from ..test_cli import claims_rows


@pytest.fixture
def three_runs(tmp_path) -> dict[str, pd.DataFrame]:
    """Three runs' claims tables in results/: a and b with the recipe's verdict, c without; c lacks C3."""
    rows = claims_rows({"C2": "holds", "C10": "absent", "C3": "opposite"})
    tables = {"a": rows.assign(recipe_verdict=["holds", "opposite", "absent"], recipe_effect=[0.5, float("nan"), 2.0]),
              "b": rows.assign(verdict=["absent", "absent", "holds"], effect=[0.1, 0.2, 0.3],
                               recipe_verdict=["not decidable", "holds", "holds"], recipe_effect=[1.5, 2.5, 3.5]),
              "c": claims_rows({"C2": "not run", "C10": "opposite"}).assign(effect=[float("nan"), -1.0])}
    for run, table in tables.items():
        (tmp_path / "results" / run / "claims").mkdir(parents=True)
        table.to_parquet(tmp_path / "results" / run / "claims" / "claims.parquet")
    return tables


def test_the_table_has_a_row_per_claim_and_each_runs_verdicts_and_effects_recipe_first(three_runs):
    grid = claims_grid(three_runs)
    assert grid["claim"].tolist() == ["C2", "C3", "C10"]  # by number
    assert list(grid.columns) == ["claim", "panel", "a recipe", "a recipe effect", "a verdict", "a effect",
                                  "b recipe", "b recipe effect", "b verdict", "b effect", "c verdict", "c effect"]
    assert grid["a recipe"].tolist() == ["holds", "absent", "opposite"]
    assert grid["b verdict"].tolist() == ["absent", "holds", "absent"]
    assert grid["c verdict"].tolist() == ["not run", "-", "opposite"] and pd.isna(grid.loc[1, "c effect"])
    verdicts, effects, recipe = headline(grid, ["a", "b", "c"])
    assert verdicts.loc["C10"].tolist() == ["opposite", "holds", "opposite"]
    assert effects.loc["C10"].tolist() == [0.4, 2.5, -1.0]  # a's recipe has no number there: its seed's effect
    assert recipe.loc["C10"].tolist() == [True, True, False]  # c has no recipe: its selected seed's verdict


def test_where_the_recipe_did_not_decide_the_headline_is_the_selected_seeds_and_not_run_shows_no_effect():
    rows = claims_rows({"C2": "holds", "C3": "not run"}).assign(effect=[0.7, 0.2], recipe_verdict=["not run", "not run"],
                                                                recipe_effect=[float("nan"), 0.9])
    verdicts, effects, recipe = headline(claims_grid({"a": rows}), ["a"])
    assert verdicts["a"].tolist() == ["holds", "not run"] and recipe["a"].tolist() == [False, False]
    assert effects.loc["C2", "a"] == 0.7 and np.isnan(effects.loc["C3", "a"])  # the seed's effect; none where not run


def test_the_heatmap_colours_each_cell_by_its_verdict_and_prints_its_effect(three_runs):
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    grid = claims_grid(three_runs)
    fig = heatmap_figure(grid, ["a", "b", "c"], plt)
    try:
        ax = fig.axes[0]
        cells = {p.get_label(): to_hex(p.get_facecolor()) for p in ax.patches}
        colour = {verdict: to_hex(c) for verdict, c in VERDICT_COLOURS.items()}
        assert cells["C2 a"] == colour["holds"] and cells["C2 b"] == colour["not decidable"]
        assert cells["C10 c"] == colour["opposite"] and cells["C3 c"] == "#ffffff"
        assert [t.get_text() for t in ax.texts] == ["0.5", "1.5", "2", "3.5", "0.4", "2.5", "-1*"]  # c: its seed's
        assert [t.get_text() for t in ax.get_yticklabels()] == ["C2", "C3", "C10"]
    finally:
        plt.close(fig)


def test_compare_claims_writes_the_table_and_the_heatmap_of_three_runs(three_runs, tmp_path, capsys, monkeypatch):
    monkeypatch.chdir(tmp_path)
    assert main(["compare-claims", "a", "b", "c", "--out", "grid.parquet", "--heatmap", "grid.png"]) == 0
    out = capsys.readouterr().out
    assert out.splitlines()[0].split()[:4] == ["claim", "panel", "a", "recipe"] and "wrote grid.png" in out
    assert pd.read_parquet("grid.parquet").equals(claims_grid(three_runs))
    assert (tmp_path / "grid.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert main(["compare-claims", "a", "b", "--out", "two.csv"]) == 0
    assert "recipe verdicts: the same for 0 of 3 claims" in capsys.readouterr().out  # the two-run output, as before
    assert pd.read_csv("two.csv")["a recipe"].tolist() == ["holds", "absent", "opposite"]


@pytest.mark.parametrize("args, message", [
    (["a"], "compare-claims needs two or more runs, got 1"),
    (["a", "missing"], "no claims table for 'missing'"),
    (["a", "b", "--out", "grid.txt"], "--out grid.txt: the table is written as .parquet or .csv"),
    (["a", "--sweep", "analysis.claims_alpha=", "--scale", "smoke"], "sweep: 'analysis.claims_alpha=' is not"),
])
def test_bad_input_is_one_line_and_writes_nothing(three_runs, tmp_path, capsys, monkeypatch, args, message):
    monkeypatch.chdir(tmp_path)
    assert main(["compare-claims", *args, "--heatmap", "grid.png"]) == 2
    err = capsys.readouterr().err
    assert message in err and len(err.strip().splitlines()) == 1
    assert not (tmp_path / "grid.png").exists()


def test_compare_claims_names_a_sweeps_runs_as_the_workflow_does(three_runs, tmp_path, capsys, monkeypatch):
    """The sweep's first point is the smoke run itself (its own claims_resamples); the second is not there yet."""
    monkeypatch.chdir(tmp_path)
    (tmp_path / "results" / "a").rename(tmp_path / "results" / "smoke")
    assert main(["compare-claims", "--sweep", "analysis.claims_resamples=100,400", "--scale", "smoke"]) == 2
    err = capsys.readouterr().err
    assert "no claims table for 'smoke-" in err and "'smoke'" not in err


def test_a_sweeps_points_are_named_by_their_values_and_each_interval_by_its_alpha(tmp_path, capsys, monkeypatch):
    from efish.sweep import sweep_points

    monkeypatch.chdir(tmp_path)
    sweep = "analysis.claims_alpha=0.05,0.01"
    points = sweep_points("smoke", [], sweep)
    assert [label for _, label in points] == ["analysis.claims_alpha=0.05", "analysis.claims_alpha=0.01"]
    for (run, _), alpha in zip(points, (0.05, 0.01), strict=True):
        folder = tmp_path / "results" / run / "claims"
        folder.mkdir(parents=True)
        claims_rows({"C2": "holds"}).to_parquet(folder / "claims.parquet")
        (folder / "config.yaml").write_text(f"analysis:\n  claims_alpha: {alpha}\n")
    assert main(["compare-claims", "--sweep", sweep, "--scale", "smoke", "--out", "grid.csv"]) == 0
    printed = capsys.readouterr().out
    assert "analysis.claims_alpha=0.01 effect [CI, alpha 0.01]" in printed
    assert "analysis.claims_alpha=0.05 effect [CI, alpha 0.05]" in printed
    assert f"analysis.claims_alpha=0.01: {points[1][0]}" in printed  # which folder each label is
    assert "analysis.claims_alpha=0.01 verdict" in pd.read_csv(tmp_path / "grid.csv").columns
