"""Panels: the registry is consistent, panels draw from real-shaped tables, missing data is said, not faked."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

from efish import layout
from efish.analysis.behaviour import food_per_agent_episode
from efish.analysis.behaviour import food_vs_size as fit_food_vs_size
from efish.figures import fig3
from efish.figures.registry import PANELS, figures, panels_for
from efish.figures.render import input_paths, load_tables, render_figure, render_panel
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


def test_every_input_is_a_table_of_the_layout():
    """Each path a panel reads is an assay, analysis or stacked top-seed table (layout.parse_table reads it), or a
    training, ranking or scene file of the layout."""
    others = {layout.training_file(layout.seed_name("{seed}"), "metrics.parquet"), layout.RANKING}
    for panel in PANELS.values():
        for path in panel.tables.values():
            parsed = layout.parse_table(path)
            if parsed is None:
                scene = layout.scene_table(path.removeprefix("scenes/").removesuffix(".parquet"))
                assert path in {*others, scene}, (panel.key, path)
            else:
                rebuilt = {"assays": lambda t: layout.assay_table(t.assay, t.table),
                           "analysis": lambda t: layout.analysis_table(t.analysis, t.assay, t.table),
                           "seeds": lambda t: layout.stacked_seeds_table(t.assay)}[parsed.kind](parsed)
                assert rebuilt == path, (panel.key, path)


def test_panels_read_the_conditions_of_every_assay_they_read(tmp_path):
    panel = PANELS["fig5/I"]  # the bot assay's reach rates
    assert panel.assays() == {"bot"}
    assert panel.conditions == {"conditions/bot": "assays/bot/conditions.parquet"}
    assert input_paths(panel, tmp_path, seeds=2)["conditions/bot"] == [tmp_path / "assays/bot/conditions.parquet"]
    assert set(PANELS["fig3/P"].conditions) == {"conditions/patchy4"}
    assert set(PANELS["supp/idi_histogram"].conditions) == {"conditions/patchy4", "conditions/wide2"}
    for key in ("fig1/A", "supp/training_curves", "supp/top_seeds_food"):  # schematic, training, top seeds: none
        assert not PANELS[key].conditions and not PANELS[key].settings and PANELS[key].tables == PANELS[key].inputs
    assert PANELS["fig5/I"].settings == {"settings/onepatch/bot": "analysis/onepatch/bot/analysis_settings.parquet"}
    for panel in PANELS.values():
        jobs = {(t.analysis, t.assay) for p in panel.inputs.values() if (t := layout.parse_table(p)) and t.analysis}
        assert set(panel.tables) == (set(panel.inputs) | {f"conditions/{a}" for a in panel.assays()}
                                     | {f"settings/{analysis}/{assay}" for analysis, assay in jobs})


def test_a_missing_conditions_table_says_to_rerun_the_assay(synthetic_results, tmp_path):
    results = tmp_path / "results"
    for name in PANELS["fig3/O"].inputs.values():
        (results / name).parent.mkdir(parents=True, exist_ok=True)
        (results / name).write_bytes((synthetic_results / name).read_bytes())
    with pytest.raises(ValueError, match=r"needs .*assays/patchy4/conditions\.parquet.*rerun the assay"):
        load_tables(PANELS["fig3/O"], results, seeds=2)


def test_a_missing_settings_table_says_to_rerun_the_analysis(synthetic_results, tmp_path):
    panel, results = PANELS["fig6/I"], tmp_path / "results"
    for name in [*panel.inputs.values(), *panel.conditions.values()]:
        (results / name).parent.mkdir(parents=True, exist_ok=True)
        (results / name).write_bytes((synthetic_results / name).read_bytes())
    with pytest.raises(ValueError, match=r"needs .*analysis/dynamics/wide2/analysis_settings\.parquet.*rerun the "
                                         r"analysis"):
        load_tables(panel, results, seeds=2)


def test_seed_paths_expand_over_every_seed(tmp_path):
    paths = input_paths(PANELS["supp/training_curves"], tmp_path, seeds=3)
    assert [p.parent.name for p in paths["metrics"]] == ["seed_1", "seed_2", "seed_3"]


def test_a_figure_draws_each_panel_and_its_page(synthetic_results, tmp_path):
    panels = figures()["fig2"]
    written = render_figure("fig2", panels, synthetic_results, tmp_path, seeds=2)
    assert {p.name for p in written["fig2"]} == {"fig2.png", "fig2.pdf"}
    for panel in panels:
        assert written[panel.key] == [tmp_path / "fig2" / f"{panel.name}.{ext}" for ext in ("png", "pdf")]
        assert all(path.is_file() for path in written[panel.key])


def test_a_figure_with_a_missing_table_writes_nothing(synthetic_results, tmp_path):
    """Every table is read before the first drawing: no partial outputs."""
    import shutil

    results = shutil.copytree(synthetic_results, tmp_path / "results")  # the fixture is shared: a copy to break
    (results / "assays/homing/steps.parquet").unlink()
    with pytest.raises(ValueError, match="which does not exist"):
        render_figure("fig2", figures()["fig2"], results, tmp_path / "out", seeds=2)
    assert not (tmp_path / "out").exists()


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


def rendered_text(rst: str) -> tuple[str, list[str]]:
    """The plain text docutils renders from ``rst`` and its system messages (warnings and errors)."""
    import io

    from docutils.core import publish_doctree

    stream = io.StringIO()
    tree = publish_doctree(rst, settings_overrides={"report_level": 2, "halt_level": 5, "warning_stream": stream})
    return " ".join(tree.astext().split()), stream.getvalue().splitlines()


@pytest.mark.parametrize("caption", ["colour = |E| over the free-space |E|", "*x* and name_ and a `b` \\ c",
                                     "o marks the start, * each pellet eaten", "plain text"])
def test_a_report_caption_renders_as_written(caption):
    from efish.figures.panel import rst_text

    assert rendered_text(rst_text(caption)) == (caption, [])
    if "|" in caption:  # the defect the escaping fixes: unescaped, |E| is an undefined substitution
        assert rendered_text(caption)[1]


def test_every_panel_caption_renders_in_the_report_as_written():
    for key, panel in PANELS.items():
        text, messages = rendered_text(f"- **{key}**: {panel.report_caption}")
        assert messages == [] and text == f"{key}: {' '.join(panel.caption.split())}", key
