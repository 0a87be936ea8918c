"""Panels: the registry is consistent, panels draw from real-shaped tables, missing data is said, not faked."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

from efish.analysis.behaviour import food_per_agent_episode
from efish.analysis.behaviour import food_vs_size as fit_food_vs_size
from efish.figures import fig3
from efish.figures.registry import PANELS, figures, panels_for
from efish.figures.render import input_paths, load_tables, render_page, render_panel
from efish.figures.style import panel_style
from efish.rollout.schema import EPISODES


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


def test_registry_keys_and_inputs_are_consistent():
    for key, panel in PANELS.items():
        assert key == f"{panel.figure}/{panel.name}"
        assert panel.caption and callable(panel.draw)  # a schematic panel reads no table
        assert all(path.endswith(".parquet") for path in panel.inputs.values())
    assert sum(len(p) for p in figures().values()) == len(PANELS)


def test_panels_need_the_assays_they_read():
    without_assays = {p.key for p in panels_for([])}
    assert {"supp/training_curves", "supp/seed_landscape"} <= without_assays
    assert all(not PANELS[k].assays() and not PANELS[k].top_seed_assays() for k in without_assays)
    assert "supp/top_seeds_food" in {p.key for p in panels_for(["patchy4"], ["patchy4"])}
    assert "supp/top_seeds_food" not in {p.key for p in panels_for(["patchy4"])}
    assert "fig3/M" in {p.key for p in panels_for(["patchy4"])}
    assert "fig2/B" not in {p.key for p in panels_for(["patchy4"])}


def test_seed_paths_expand_over_every_seed(tmp_path):
    paths = input_paths(PANELS["supp/training_curves"], tmp_path, seeds=3)
    assert [p.parent.name for p in paths["metrics"]] == ["seed_1", "seed_2", "seed_3"]


def test_a_page_holds_every_panel_of_its_figure(synthetic_results, tmp_path):
    written = render_page("fig2", figures()["fig2"], synthetic_results, tmp_path, seeds=2)
    assert {p.name for p in written} == {"fig2.png", "fig2.pdf"}


def test_per_seed_tables_carry_their_seed(synthetic_results):
    tables = load_tables(PANELS["supp/training_curves"], synthetic_results, seeds=2)
    assert sorted(tables["metrics"]["seed"].unique()) == [1, 2]


def test_a_missing_table_is_one_clear_error(tmp_path):
    with pytest.raises(ValueError, match=r"needs .*\.parquet, which does not exist"):
        render_panel("fig3/M", tmp_path, tmp_path, seeds=1)


def test_unknown_panel_names_the_choices(tmp_path):
    with pytest.raises(ValueError, match="unknown panel 'fig9/Z'"):
        render_panel("fig9/Z", tmp_path, tmp_path, seeds=1)


def _food_tables(episodes: pd.DataFrame) -> dict[str, pd.DataFrame]:
    """The behaviour analysis tables panel fig3/M reads: food per agent-episode and the OLS of food on size."""
    return {"food_per_agent": food_per_agent_episode(episodes), "food_vs_size": fit_food_vs_size(episodes)}


def test_food_vs_size_fits_the_known_line():
    with panel_style() as plt:
        fig, ax = plt.subplots()
        fig3.food_vs_size(_food_tables(episodes_table(n_episodes=10)), ax)
        label = ax.get_legend().get_texts()[0].get_text()
        plt.close(fig)
    slope = float(label.split()[1].rstrip(","))
    assert slope == pytest.approx(8, abs=0.5)  # food = round(2 + 8 size)


def test_an_empty_table_is_said_on_the_panel():
    with panel_style() as plt:
        fig, ax = plt.subplots()
        fig3.food_vs_size(_food_tables(episodes_table().iloc[:0]), ax)
        texts = [t.get_text() for t in ax.texts]
        plt.close(fig)
    assert any(t.startswith("no data") for t in texts)


def test_efish_figure_writes_a_panel_with_its_config(synthetic_results, tmp_path):
    from efish.cli import main

    out = tmp_path / "figs"
    assert main(["figure", "fig3/M", "scale=smoke", "--results", str(synthetic_results), "--out", str(out)]) == 0
    assert (out / "fig3/M.png").is_file() and (out / "fig3/M.pdf").is_file()
    assert "name: smoke" in (out / "fig3/config.yaml").read_text()
    assert (out / "fig3/M.provenance.json").is_file()


def test_efish_figure_rejects_an_unknown_figure_in_one_line(tmp_path, capsys):
    from efish.cli import main

    assert main(["figure", "fig99", "--results", str(tmp_path), "--out", str(tmp_path / "f")]) == 2
    err = capsys.readouterr().err.strip()
    assert err.startswith("efish: error: unknown figure 'fig99'") and "\n" not in err
    assert not (tmp_path / "f").exists()
