"""Fig 4 panels: every panel renders from real-shaped tables, drawn values and stars are the tables' own."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

from efish.figures import fig4
from efish.figures.registry import PANELS
from efish.figures.render import load_tables, render_panel
from efish.figures.style import assay_conditions, box_strip, panel_style

from ..helpers import draw_panel_axes as draw
from ..helpers import panel_texts as texts

FIG4 = [key for key in PANELS if key.startswith("fig4/")]


def points_at(ax, x: float) -> np.ndarray:
    """Sorted y of every strip point drawn within 0.4 of category position ``x``."""
    ys = [off[np.abs(off[:, 0] - x) < 0.4, 1] for c in ax.collections if len(off := c.get_offsets())]
    return np.sort(np.concatenate(ys)) if ys else np.array([])


def summary(values: dict[str, list[float]], measure: str = "food_total") -> pd.DataFrame:
    rows = [{"condition": c, "episode": e, measure: v, "reason": ""} for c, vs in values.items()
            for e, v in enumerate(vs)]
    return pd.DataFrame(rows)


def dunnett(groups: dict[str, str], control: str, measure: str = "food_total") -> pd.DataFrame:
    return pd.DataFrame([{"test": "dunnett", "group": g, "control": control, "stars": s, "measure": measure,
                          "p": 0.01, "reason": ""} for g, s in groups.items()])


def test_every_letter_of_spec_13_is_registered():
    assert sorted(k.split("/")[1] for k in FIG4) == list("ABCDEFGHIJKLMN")


@pytest.mark.parametrize("key", FIG4)
def test_every_panel_renders_with_labelled_axes(key, synthetic_results, tmp_path):
    written = render_panel(key, synthetic_results, tmp_path, seeds=2)
    assert all(p.stat().st_size > 1000 for p in written)
    ax = draw(key, load_tables(PANELS[key], synthetic_results, seeds=2))
    said_missing = any(t.startswith("no data") for t in texts(ax))
    assert said_missing or (ax.get_xlabel() and ax.get_ylabel()), key


def test_conditions_follow_the_recorded_order_with_the_control_first(recorded):
    present = ["A_K", "K", "M_A", "M_A_K", "M_K", "none"]  # alphabetical, as the tables are sorted
    tables = recorded("ablation4", "mute")
    assert fig4.condition_order(tables, "ablation4", present, "M_A_K") == ["M_A_K", "M_A", "M_K", "A_K", "K", "none"]
    assert fig4.condition_order(tables, "mute", ["muted", "intact", "extra"], "intact") == ["intact", "muted",
                                                                                            "extra"]
    with pytest.raises(ValueError, match=r"no conditions/npatch \(assays/npatch/conditions.parquet\)"):
        fig4.condition_order(tables, "npatch", ["a"])
    # the order is the run's record, whatever the config files say now
    reordered = tables["conditions/ablation4"].assign(position=lambda t: t["position"].max() - t["position"])
    assert fig4.condition_order({"conditions/ablation4": reordered}, "ablation4", present) == [
        "none", "K", "A_K", "M_K", "M_A", "M_A_K"]


def test_ablation_panel_draws_the_episodes_and_the_dunnett_stars_of_the_table(recorded):
    values = {"M_A_K": [4.0, 6.0, 5.0], "M_A": [1.0, 2.0, 3.0], "none": [0.0, 1.0, 0.0]}
    tests = pd.concat([dunnett({"M_A": "**", "none": "ns"}, "M_A_K"),
                       dunnett({"M_A": "****", "none": "****"}, "M_A_K", measure="theil_t")])  # other measure
    ax = draw("fig4/B", {"summary": summary(values), "tests": tests, **recorded("ablation4")})
    assert [t.get_text() for t in ax.get_xticklabels()] == ["M+A+K", "M+A", "none"]
    for i, cond in enumerate(["M_A_K", "M_A", "none"]):
        np.testing.assert_allclose(points_at(ax, i), sorted(values[cond]))
    assert sorted(texts(ax)) == ["**", "ns"]


def test_a_condition_without_a_test_row_is_marked_n_a(recorded):
    ax = draw("fig4/G", {"summary": summary({"control": [1.0, 2.0], "self_only": [0.0, 1.0]}),
                         "tests": dunnett({}, "control").reindex(columns=["group", "control", "stars", "measure"]),
                         **recorded("collective")})
    assert texts(ax) == ["n/a"]


def test_collective_shows_the_authors_self_only_mode_beside_the_clean_gate(recorded):
    values = {"control": [6.0, 6.0], "self_only": [5.0, 4.0], "self_only_authors": [5.5, 5.0], "cons_only": [6.0]}
    tests = dunnett({"self_only": "*", "self_only_authors": "**", "cons_only": "ns"}, "control")
    ax = draw("fig4/G", {"summary": summary(values), "tests": tests, **recorded("collective")})
    labels = [t.get_text() for t in ax.get_xticklabels()]
    assert labels == ["control", "self only\n(clean gate)", "self only\n(authors' mode)", "cons only"]
    np.testing.assert_allclose(points_at(ax, 2), [5.0, 5.5])
    assert sorted(texts(ax)) == ["*", "**", "ns"]
    assert "authors' mode" in PANELS["fig4/G"].caption and "wall_distortion" in PANELS["fig4/G"].caption


def test_mute_draws_the_results_design_first_and_the_methods_design_beside_it(recorded):
    values = {"intact": [6.0, 7.0], "muted": [3.0, 4.0], "intact4": [20.0, 22.0], "muted4": [18.0]}
    tests = pd.concat([dunnett({"muted": "***", "intact4": "****", "muted4": "****"}, "intact"),
                       dunnett({"muted4": "*"}, "intact4", measure="theil_t")])  # another measure: not drawn
    ax = draw("fig4/I", {"summary": summary(values), "tests": tests, **recorded("mute")})
    for x, cond in [(0, "intact"), (1, "muted"), (3, "intact4"), (4, "muted4")]:  # an empty slot between designs
        np.testing.assert_allclose(points_at(ax, x), sorted(values[cond]))
    assert [t.get_text() for t in ax.get_xticklabels()] == ["none\nmuted", "agent 1\nmuted", "",
                                                             "none\nmuted", "agent 0\nmuted"]
    designs = [t.get_text() for t in ax.get_xticklabels(minor=True)]
    assert designs == ["2 agents, uniform 70x70\n(Results, decides C12)", "4 agents, patchy 70x70\n(Methods)"]
    # stars only from a row of exactly the pair: muted4 vs intact (the Dunnett control) is not the 4-agent test
    assert sorted(texts(ax)) == ["***", "n/a"]


def test_mute_designs_follow_the_assay_config(recorded):
    configs = assay_conditions(recorded("mute"), "mute")
    assert list(configs) == [c for intact, muted, _ in fig4.MUTE_DESIGNS for c in (intact, muted)]
    (intact, muted, _), (intact4, muted4, _) = fig4.MUTE_DESIGNS
    assert (configs[intact].env.n_agents, configs[intact].arena.layout, configs[muted].env.muted) == (2, "uniform", [1])
    assert (configs[intact4].env.n_agents, configs[intact4].arena.layout, configs[muted4].env.muted) == (4, "patchy",
                                                                                                       [0])
    assert configs[intact].assay.seed == configs[intact4].assay.seed  # paired episodes within each design


def test_mute_design_labels_follow_the_recorded_arena_and_agents(recorded):
    """A run in a 100 x 90 cm arena labels its designs with that arena (the mute conditions set agents, not size)."""
    overridden = recorded("mute", overrides=("arena.width_cm=100", "arena.height_cm=90"))
    groups, labels = fig4.mute_design_labels(assay_conditions(overridden, "mute"))
    assert groups == ["2 agents, uniform 100x90\n(Results, decides C12)", "4 agents, patchy 100x90\n(Methods)"]
    assert labels["muted"] == "agent 1\nmuted"


def test_a_measure_without_finite_values_says_why(recorded):
    frame = summary({"intact": [np.nan], "muted": [np.nan]}, "mean_nn_dist_cm").assign(reason="no other agent")
    ax = draw("fig4/J", {"summary": frame, "tests": dunnett({"muted": "n/a"}, "intact", "mean_nn_dist_cm"),
                         **recorded("mute")})
    assert any("no other agent" in t for t in texts(ax))


def test_patchy_and_uniform_are_drawn_side_by_side_without_stars():
    ax = draw("fig4/K", {"patchy": summary({"control": [10.0, 12.0]}), "uniform": summary({"control": [3.0]})})
    np.testing.assert_allclose(points_at(ax, 0), [10.0, 12.0])
    np.testing.assert_allclose(points_at(ax, 1), [3.0])
    assert texts(ax) == []


def test_npatch_ratio_is_iso_food_over_the_mean_free_food_at_the_same_n():
    frame = summary({"iso_1": [2.0, 4.0], "free_1": [6.0, 6.0], "iso_2": [1.0, 1.0], "free_2": [4.0, 0.0],
                     "iso_3": [1.0], "free_3": [0.0]})  # n = 3: the free series ate nothing, no ratio
    ax = draw("fig4/M", {"summary": frame})
    line = ax.containers[0].lines[0]
    np.testing.assert_allclose(line.get_ydata(), [0.5, 0.5])  # (2/6 + 4/6) / 2 and 1/2
    np.testing.assert_allclose(np.round(line.get_xdata()), [1, 2])


def test_npatch_theil_has_one_mean_line_per_series():
    frame = summary({"iso_1": [0.1, 0.3], "free_1": [0.5], "iso_2": [0.2], "free_2": [0.7]}, "theil_t")
    ax = draw("fig4/N", {"summary": frame})
    means = {c.get_label(): c.lines[0].get_ydata() for c in ax.containers}
    np.testing.assert_allclose(means["iso"], [0.2, 0.2])
    np.testing.assert_allclose(means["free"], [0.5, 0.7])


def test_npatch_conditions_must_name_series_and_patch_number():
    with pytest.raises(ValueError, match="iso_<n> or free_<n>"):
        fig4.npatch_frame(summary({"control": [1.0]}))


def test_box_strip_rejects_a_missing_column():
    with panel_style() as plt:
        fig = plt.figure()
        with pytest.raises(ValueError, match="box_strip needs columns"):
            box_strip(fig.add_subplot(), pd.DataFrame({"condition": ["a"]}), "condition", "food_total", ["a"],
                      {"a": "k"})
        plt.close(fig)
