"""Fig 6 panels: every panel renders from real-shaped tables, drawn values are the tables' own, gaps are said."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

from efish.figures import fig6
from efish.figures.registry import PANELS
from efish.figures.render import load_tables, render_panel

from ..helpers import draw_panel_axes as draw
from ..helpers import panel_texts as texts

FIG6 = [key for key in PANELS if key.startswith("fig6/")]
#: Panels whose data no analysis table holds yet: they say so on themselves.
NOT_ANALYSED: set[str] = set()


def test_every_letter_of_spec_13_is_registered():
    assert sorted(k.split("/")[1] for k in FIG6) == list("ABCDEFGHIJ")


@pytest.mark.parametrize("key", FIG6)
def test_every_panel_renders_with_labelled_axes(key, synthetic_results, tmp_path):
    written = render_panel(key, synthetic_results, tmp_path, seeds=2)
    assert all(p.stat().st_size > 1000 for p in written)
    ax = draw(key, load_tables(PANELS[key], synthetic_results, seeds=2))
    said_missing = any(t.startswith("no data") for t in texts(ax))
    assert said_missing == (key in NOT_ANALYSED), key
    assert said_missing or (ax.get_xlabel() and ax.get_ylabel()), key


def test_decoding_bars_are_the_skills_best_first_without_unscored_targets(recorded):
    table = pd.DataFrame({"condition": "control", "target": ["dist_wall_cm", "dist_agent_cm", "size", "dist_food_cm"],
                          "skill": [0.2, 0.6, np.nan, -0.1], "reason": ["", "", "constant target", ""]})
    ax = draw("fig6/E", {"decoding": table, **recorded("wide2")})
    widths = [p.get_width() for p in ax.patches if p.get_height() > 0]
    np.testing.assert_allclose(widths, [0.6, 0.2, -0.1])
    assert [t.get_text() for t in ax.get_yticklabels()] == ["nearest agent: log distance", "wall: log distance",
                                                            "food: log distance"]


@pytest.mark.parametrize("with_column", [True, False])
def test_readouts_are_drawn_hatched_below_the_sensed_targets_and_not_ranked_among_them(with_column, recorded):
    """Decoding rule: the copies of the network's input (own turn, EOD and size, its sensor summaries) are drawn as
    readouts, after every sensed target, even when they decode best; a table without the readout column (an
    earlier run) is marked by target."""
    table = pd.DataFrame({"condition": "control",
                          "target": ["turn_rad", "dist_agent_cm", "eod", "dist_wall_cm", "log_morm_sensed"],
                          "readout": [True, False, True, False, True], "skill": [0.8, 0.3, 0.6, 0.1, 0.5],
                          "reason": ""})
    ax = draw("fig6/E", {"decoding": table if with_column else table.drop(columns="readout"), **recorded("wide2")})
    bars = [p for p in ax.patches if p.get_height() > 0]
    np.testing.assert_allclose([p.get_width() for p in bars], [0.3, 0.1, 0.8, 0.6, 0.5])
    assert [t.get_text() for t in ax.get_yticklabels()] == ["nearest agent: log distance", "wall: log distance",
                                                            "turn (readout)", "own EOD (readout)",
                                                            "log reading (M, sensed) (readout)"]
    assert [bool(p.get_hatch()) for p in bars] == [False, False, True, True, True]
    assert any(line.get_linestyle() == "--" for line in ax.get_lines())  # the line between the two groups


def test_decoding_without_any_skill_says_why(recorded):
    table = pd.DataFrame({"condition": ["electric"], "target": ["size"], "skill": [np.nan],
                          "reason": ["constant target"]})
    ax = draw("fig6/D", {"decoding": table, **recorded("homing")})
    assert any("constant target" in t for t in texts(ax))


def test_food_decoding_bars_pair_near_and_far_skills_per_variable(recorded, analysed):
    table = pd.DataFrame({"condition": "control", "food": ["near", "near", "far", "far"],
                          "target": ["dist_food_cm", "bearing_food_rad"] * 2, "skill": [0.5, 0.3, -0.05, np.nan],
                          "reason": ["", "", "", "fewer than 2 groups (episodes) with finite rows (1)"]})
    wide2 = {**recorded("wide2"), **analysed("dynamics", "wide2")}
    ax = draw("fig6/F", {"food_decoding": table, **wide2})
    widths = sorted(p.get_width() for p in ax.patches if p.get_height() > 0 and np.isfinite(p.get_width()))
    np.testing.assert_allclose(widths, [-0.05, 0.3, 0.5])
    assert {t.get_text() for t in ax.get_yticklabels()} == {"food: log distance", "food: bearing"}
    assert [t.get_text() for t in ax.get_legend().get_texts()] == ["near", "far"]
    empty = draw("fig6/F", {"food_decoding": table.assign(skill=np.nan), **wide2})
    assert any("fewer than 2 groups" in t for t in texts(empty))


def test_plsc_bars_are_the_table_values_and_an_empty_bin_says_n_a(recorded):
    table = pd.DataFrame({"lo_cm": [0.0, 10.0, 100.0], "hi_cm": [10.0, 100.0, np.inf], "n_steps": [3, 50, 40],
                          "n_significant": [np.nan, 3.0, 0.0], "s_1": [np.nan, 2.5, 1.0],
                          "reason": ["need T >= 10", "", ""], "condition": "control"})
    ax = draw("fig6/H", {"plsc": table, **recorded("wide2")})
    np.testing.assert_allclose([p.get_height() for p in ax.patches], [3.0, 0.0])
    assert sorted(texts(ax)) == ["0", "3", "n/a"]
    assert [t.get_text() for t in ax.get_xticklabels()] == ["<= 10", "10-100", "> 100"]


def test_power_by_size_puts_each_agent_in_its_size_class_and_drops_equal_sizes():
    dims = pd.DataFrame({"condition": "control", "episode": [0, 0, 1, 1, 2, 2], "agent": [0, 1] * 3,
                         "wideband_power": [1.0, 2.0, 4.0, 3.0, 9.0, 9.5], "reason": ""})
    episodes = pd.DataFrame({"condition": "control", "episode": [0, 0, 1, 1, 2, 2], "agent": [0, 1] * 3,
                             "size": [0.2, 0.8, 0.9, 0.1, 0.5, 0.5]})
    tests = pd.DataFrame({"measure": ["near_far", "size"], "stars": ["XNEAR", "XSIZE"]})
    ax = draw("fig6/J", {"dims": dims, "episodes": episodes, "tests": tests})
    assert [t for t in texts(ax) if t.startswith("X")] == ["XSIZE"]
    by_x = {}
    for c in ax.collections:
        for x, y in c.get_offsets():
            by_x.setdefault(round(x), []).append(y)
    assert sorted(by_x[0]) == [1.0, 3.0] and sorted(by_x[1]) == [2.0, 4.0]


def test_group_size_and_knollenorgans_come_from_the_recorded_conditions(recorded):
    frame = fig6.groupsize_frame(pd.DataFrame({"condition": ["n1_K", "n3_noK", "other"], "d_eff": [1.0, 2.0, 3.0]}),
                                 recorded("groupsize"))
    assert frame["n_agents"].tolist() == [1, 3]  # "other" is no condition the run recorded
    assert frame["knollenorgans"].tolist() == ["K on", "K off"]
    with pytest.raises(ValueError, match="no conditions/groupsize"):
        fig6.groupsize_frame(pd.DataFrame({"condition": ["n1_K"]}), {})


def test_deff_vs_group_size_means_per_knollenorgan_state(recorded):
    dims = pd.DataFrame({"condition": ["n1_K", "n1_K", "n2_K", "n1_noK", "n2_noK"], "d_eff": [2.0, 4.0, 5.0, 1.0, 1.5],
                         "reason": ""})
    tests = pd.DataFrame({"group": ["K", "noK"], "effect": [0.5, np.nan], "stars": ["XK", "n/a"]})
    ax = draw("fig6/B", {"dims": dims, "tests": tests, **recorded("groupsize")})
    assert texts(ax)[-1] == "K on: rho +0.50 XK\nK off: n/a"
    means = {c.get_label(): c.lines[0].get_ydata() for c in ax.containers}
    np.testing.assert_allclose(means["K on"], [3.0, 5.0])
    np.testing.assert_allclose(means["K off"], [1.0, 1.5])


def test_power_near_far_draws_each_agent_episode_and_the_wilcoxon_stars(recorded, analysed):
    power = pd.DataFrame({"condition": "control", "episode": [0, 0, 1, 1], "agent": 0,
                          "where": ["near", "far"] * 2, "wideband_power": [1.0, 3.0, 2.0, 5.0], "reason": ""})
    tests = pd.DataFrame({"measure": ["near_far", "size"], "stars": ["XNEAR", "XSIZE"]})
    wide2 = {**recorded("wide2"), **analysed("dynamics", "wide2")}
    ax = draw("fig6/I", {"power": power, "tests": tests, **wide2})
    by_x = {}
    for c in ax.collections:
        for x, y in c.get_offsets():
            by_x.setdefault(round(x), []).append(y)
    assert sorted(by_x[0]) == [1.0, 2.0] and sorted(by_x[1]) == [3.0, 5.0]
    assert [t for t in texts(ax) if t.startswith("X")] == ["XNEAR"]
    small = draw("fig6/I", {"power": power.assign(wideband_power=power["wideband_power"] * 1e-3), "tests": tests,
                            **wide2})
    drawn = sorted(y for c in small.collections for _, y in c.get_offsets())
    np.testing.assert_allclose(drawn, [1.0, 2.0, 3.0, 5.0])  # in units of 10^-3, which the label names
    assert "10$^{-3}$" in small.get_ylabel()
    nan_row = pd.DataFrame([{"where": np.nan, "wideband_power": np.nan, "reason": "the rollout table lacks x"}])
    ax = draw("fig6/I", {"power": nan_row, "tests": tests, **wide2})
    assert any("lacks x" in t for t in texts(ax))


def test_thresholds_named_on_the_panels_are_the_analysis_jobs(recorded, analysed):
    """The near / far distances on panel I's ticks and panel F's legend, and panel A's variance fraction, are the
    analysis settings the dynamics job recorded beside its tables (analysis_settings.parquet): not the schema's
    defaults, nor the analysis settings the assay's conditions happen to hold."""
    wide2 = {**recorded("wide2", overrides=("analysis.claims_near_cm=9", "analysis.claims_far_cm=99",
                                            "analysis.claims_food_near_cm=1")),
             **analysed("dynamics", "wide2", overrides=("analysis.claims_near_cm=7", "analysis.claims_far_cm=45",
                                                        "analysis.claims_food_near_cm=3"))}
    power = pd.DataFrame({"condition": "control", "episode": [0, 0], "agent": 0, "where": ["near", "far"],
                          "wideband_power": [1.0, 3.0], "reason": ""})
    ax = draw("fig6/I", {"power": power, "tests": pd.DataFrame({"measure": ["near_far"], "stars": ["*"]}), **wide2})
    assert [t.get_text() for t in ax.get_xticklabels()] == ["near (<= 7 cm)", "far (> 45 cm)"]
    table = pd.DataFrame({"condition": "control", "food": ["near", "far"], "target": "dist_food_cm",
                          "skill": [0.5, 0.1], "reason": ""})
    ax = draw("fig6/F", {"food_decoding": table, **wide2})
    assert ax.get_legend().get_title().get_text() == "food (near: <= 3 cm)"
    dims = pd.DataFrame({"condition": "control", "episode": [0, 1], "agent": 0, "d_eff": [3.0, 4.0],
                         "pcs_for_variance": [5, 6]})
    ax = draw("fig6/A", {"dims": dims, **recorded("patchy4"),
                         **analysed("dynamics", "patchy4", overrides=("analysis.variance_fraction=0.8",))})
    assert [t.get_text() for t in ax.get_xticklabels()] == ["D_eff", "PCs for 80% var."]


def test_a_panel_reads_the_settings_of_the_analysis_jobs_whose_tables_it_names():
    """Panel I reads two dynamics tables of wide2: one settings table beside them, which the job writes."""
    panel = PANELS["fig6/I"]
    assert panel.settings == {"settings/dynamics/wide2": "analysis/dynamics/wide2/analysis_settings.parquet"}
    assert set(panel.settings.items()) <= set(panel.tables.items())
