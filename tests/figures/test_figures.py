"""Panels: the registry is consistent, panels draw from real-shaped tables, missing data is said, not faked."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

from efish.analysis.selection import rank_seeds, seed_statistics
from efish.figures import fig3
from efish.figures.registry import PANELS, figures, panels_for
from efish.figures.render import input_paths, load_tables, render_page, render_panel
from efish.figures.style import panel_style
from efish.rollout.schema import EPISODES, STEPS


def episodes_table(seed: int = 0, n_episodes: int = 3) -> pd.DataFrame:
    """An episodes table whose food grows with size exactly: food = 2 + 8 * size."""
    rng = np.random.default_rng(seed)
    rows = []
    for e in range(n_episodes):
        for a, size in enumerate(rng.uniform(0, 1, 4)):
            rows.append({"condition": "control", "episode": e, "agent": a, "size": size,
                         "food_eaten": int(round(2 + 8 * size)), "eod_probability": 0.5, "bites_given": 0,
                         "bites_received": 0, "mean_nn_dist_cm": 20.0, "return": 1.0, "steps": 100,
                         "terminated": False, "success": False})
    return pd.DataFrame(rows)[EPISODES.names]


def steps_table() -> pd.DataFrame:
    """Two agents, two steps, every steps column present."""
    df = pd.DataFrame(0.0, index=range(4), columns=STEPS.names)
    df["condition"], df["episode"], df["agent"], df["t"] = "electric", 0, [0, 1, 0, 1], [0, 0, 1, 1]
    df["x_cm"], df["y_cm"] = [10.0, 50.0, 10.0, 45.0], [10.0, 50.0, 10.0, 45.0]
    return df


@pytest.fixture
def results(tmp_path):
    """A results folder holding every table the registered panels read."""
    root = tmp_path / "results"
    (root / "assays/patchy4").mkdir(parents=True)
    (root / "assays/homing").mkdir(parents=True)
    episodes_table().to_parquet(root / "assays/patchy4/episodes.parquet")
    steps_table().to_parquet(root / "assays/homing/steps.parquet")
    selection = pd.concat([episodes_table(s).assign(seed=s) for s in (1, 2)])
    (root / "analysis/selection").mkdir(parents=True)
    rank_seeds(seed_statistics(selection)).to_parquet(root / "analysis/selection/ranking.parquet")
    for s in (1, 2):
        (root / f"train/seed_{s}").mkdir(parents=True)
        pd.DataFrame({"env_steps": [100, 200, 300], "episode_return": [np.nan, 1.0, 2.0 * s]}).to_parquet(
            root / f"train/seed_{s}/metrics.parquet")
    return root


def test_registry_keys_and_inputs_are_consistent():
    for key, panel in PANELS.items():
        assert key == f"{panel.figure}/{panel.name}"
        assert panel.caption and panel.inputs and callable(panel.draw)
        assert all(path.endswith(".parquet") for path in panel.inputs.values())
    assert sum(len(p) for p in figures().values()) == len(PANELS)


def test_panels_need_the_assays_they_read():
    assert {p.key for p in panels_for([])} == {"supp/training_curves", "supp/seed_landscape"}
    assert "fig3/M" in {p.key for p in panels_for(["patchy4"])}
    assert "fig2/B" not in {p.key for p in panels_for(["patchy4"])}


def test_seed_paths_expand_over_every_seed(tmp_path):
    paths = input_paths(PANELS["supp/training_curves"], tmp_path, seeds=3)
    assert [p.parent.name for p in paths["metrics"]] == ["seed_1", "seed_2", "seed_3"]


def test_every_panel_renders_png_and_pdf(results, tmp_path):
    for key in PANELS:
        written = render_panel(key, results, tmp_path / "figures", seeds=2)
        assert [p.suffix for p in written] == [".png", ".pdf"]
        assert all(p.stat().st_size > 1000 for p in written)


def test_a_page_holds_every_panel_of_its_figure(results, tmp_path):
    written = render_page("supp", figures()["supp"], results, tmp_path, seeds=2)
    assert {p.name for p in written} == {"supp.png", "supp.pdf"}


def test_per_seed_tables_carry_their_seed(results):
    tables = load_tables(PANELS["supp/training_curves"], results, seeds=2)
    assert sorted(tables["metrics"]["seed"].unique()) == [1, 2]


def test_a_missing_table_is_one_clear_error(tmp_path):
    with pytest.raises(ValueError, match="needs .*episodes.parquet, which does not exist"):
        render_panel("fig3/M", tmp_path, tmp_path, seeds=1)


def test_unknown_panel_names_the_choices(tmp_path):
    with pytest.raises(ValueError, match="unknown panel 'fig9/Z'"):
        render_panel("fig9/Z", tmp_path, tmp_path, seeds=1)


def test_food_vs_size_fits_the_known_line():
    with panel_style() as plt:
        fig, ax = plt.subplots()
        fig3.food_vs_size({"episodes": episodes_table(n_episodes=10)}, ax)
        label = ax.get_legend().get_texts()[0].get_text()
        plt.close(fig)
    slope = float(label.split()[1].rstrip(","))
    assert slope == pytest.approx(8, abs=0.5)  # food = round(2 + 8 size)


def test_an_empty_table_is_said_on_the_panel():
    with panel_style() as plt:
        fig, ax = plt.subplots()
        fig3.food_vs_size({"episodes": episodes_table().iloc[:0]}, ax)
        texts = [t.get_text() for t in ax.texts]
        plt.close(fig)
    assert any(t.startswith("no data") for t in texts)


def test_efish_figure_writes_a_panel_with_its_config(results, tmp_path):
    from efish.cli import main

    out = tmp_path / "figs"
    assert main(["figure", "fig3/M", "scale=smoke", "--results", str(results), "--out", str(out)]) == 0
    assert (out / "fig3/M.png").is_file() and (out / "fig3/M.pdf").is_file()
    assert "name: smoke" in (out / "fig3/config.yaml").read_text()
    assert (out / "fig3/M.provenance.json").is_file()


def test_efish_figure_rejects_an_unknown_figure_in_one_line(tmp_path, capsys):
    from efish.cli import main

    assert main(["figure", "fig99", "--results", str(tmp_path), "--out", str(tmp_path / "f")]) == 2
    err = capsys.readouterr().err.strip()
    assert err.startswith("efish: error: unknown figure 'fig99'") and "\n" not in err
    assert not (tmp_path / "f").exists()
