"""Fig 5 panels: roles, sizes and fps come from the conditions the run recorded, every panel renders, drawn values
are the tables' values."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

from efish.analysis.interactions import LABELS
from efish.config import compose
from efish.figures import fig5
from efish.figures.registry import PANELS
from efish.figures.render import load_tables, render_panel
from efish.figures.style import assay_conditions, panel_style

FIG5 = [key for key in PANELS if key.startswith("fig5/")]
ARENA_MAPS = {"fig5/A", "fig5/B", "fig5/C", "fig5/D"}


def draw(key: str, results, tables=None):
    """Draw panel ``key`` on a fresh axes from ``results`` (or the given ``tables``); the axes, its figure closed."""
    panel = PANELS[key]
    tables = load_tables(panel, results, seeds=2) if tables is None else tables
    with panel_style() as plt:
        fig = plt.figure()
        ax = fig.add_subplot()
        panel.draw(tables, ax)
        plt.close(fig)  # its artists stay readable; an open figure per test would pile up
    return ax


def point_values(ax) -> np.ndarray:
    """The y of every scattered point on ``ax`` (seaborn strip points are PathCollections)."""
    ys = [c.get_offsets()[:, 1] for c in ax.collections if len(c.get_offsets())]
    return np.sort(np.concatenate(ys)) if ys else np.array([])


@pytest.fixture(scope="module")
def onepatch(recorded):
    """The one-patch conditions as a run without overrides records them."""
    return assay_conditions(recorded("onepatch"), "onepatch")


def test_every_letter_of_spec_13_is_registered():
    assert sorted(k.split("/")[1] for k in FIG5) == list("ABCDEFGHIJKLMNOP")


def test_alone_controls_sit_beside_the_class_they_are_matched_to(onepatch):
    assert fig5.class_slots("B", ["A_gt_B", "A_lt_B", "B_alone_25", "B_alone_75", "B_alone_50"], onepatch) == [
        "A_lt_B", "B_alone_75", " ", "A_gt_B", "B_alone_25", "  ", "B_alone_50"]  # an unmatched control last


def test_role_rows_picks_b_in_each_condition_and_rejects_bad_roles(onepatch):
    table = pd.DataFrame({"condition": ["A_lt_B", "A_lt_B", "B_alone_75", "A_alone_25"], "agent": [0, 1, 0, 0],
                          "v": [1, 2, 3, 4]})
    rows = fig5.role_rows(table, "B", onepatch)
    assert rows["v"].tolist() == [2, 3]
    assert not any(c.startswith("A_alone") for c in rows["condition"].cat.categories)
    with pytest.raises(ValueError, match="role must be"):
        fig5.role_rows(table, "C", onepatch)


def test_bot_classes_read_size_rate_and_mobility_from_the_config(recorded):
    bots = fig5.bot_classes(assay_conditions(recorded("bot"), "bot")).set_index("condition")
    assert len(bots) == 30 and set(bots["agent"]) == {1}
    row = bots.loc["bot0.25_B0.75_rate0.5_frozen"]
    assert (row["size_class"], row["bot_eod_rate"], row["mobility"]) == ("A_lt_B", 0.5, "frozen")
    assert bots.loc["bot0.75_B0.25_rate0_moving", "mobility"] == "moving"
    assert bots.loc["bot0.5_B0.5_rate1_moving", "class_label"] == "bot=B"


@pytest.mark.parametrize("key", FIG5)
def test_panel_renders_with_labelled_axes(key, synthetic_results, tmp_path):
    written = render_panel(key, synthetic_results, tmp_path, seeds=2)
    assert [p.suffix for p in written] == [".png", ".pdf"]
    ax = draw(key, synthetic_results)
    texts = [t.get_text() for t in ax.texts]
    if not any(t.startswith("no data") for t in texts):
        assert ax.get_xlabel() and ax.get_ylabel(), key
    if key in ARENA_MAPS:
        assert (ax.get_xlabel(), ax.get_ylabel()) == ("x (cm)", "y (cm)")


def test_scene_shows_the_first_episode_at_its_first_step(synthetic_results):
    tables = load_tables(PANELS["fig5/A"], synthetic_results, 2)
    ax = draw("fig5/A", synthetic_results, tables)
    steps, food = tables["steps"], tables["food"]
    episode = steps.loc[steps["condition"] == "A_lt_B", "episode"].min()
    start = steps[(steps["condition"] == "A_lt_B") & (steps["episode"] == episode) & (steps["t"] == 0)]
    bodies = {tuple(np.round(line.get_xydata()[0], 4)) for line in ax.get_lines()}
    assert {tuple(np.round(xy, 4)) for xy in start[["x_cm", "y_cm"]].to_numpy(float)} <= bodies
    pellets = food[(food["condition"] == "A_lt_B") & (food["episode"] == episode) & (food["t_spawned"] <= 0)]
    assert ax.child_axes[0].get_title() == f"{len(pellets)} pellets at t=0"


def test_food_of_b_draws_b_food_of_every_condition(synthetic_results):
    tables = load_tables(PANELS["fig5/E"], synthetic_results, 2)
    food = tables["food"]
    configs = assay_conditions(tables, "onepatch")
    expected = fig5.role_rows(food, "B", configs)["food_eaten"].to_numpy(float)
    ax = draw("fig5/E", synthetic_results, tables)
    assert np.array_equal(point_values(ax), np.sort(expected))
    labels = [t.get_text() for t in ax.get_xticklabels()]
    # each size class beside B alone at the size B has in it, an empty slot between classes
    assert labels == ["A<B", "B alone\n0.75", "", "A=B", "B alone\n0.5", "", "A>B", "B alone\n0.25"]
    for i, cond in [(0, "A_lt_B"), (1, "B_alone_75"), (6, "A_gt_B"), (7, "B_alone_25")]:  # noqa: B007 (@cond)
        mine = fig5.role_rows(food, "B", configs).query("condition == @cond")["food_eaten"].to_numpy(float)
        ys = [off[np.abs(off[:, 0] - i) < 0.4, 1] for c in ax.collections if len(off := c.get_offsets())]
        assert np.array_equal(np.sort(np.concatenate(ys)), np.sort(mine))


def test_food_panels_read_their_stars_from_role_tests(synthetic_results):
    tables = load_tables(PANELS["fig5/E"], synthetic_results, 2)
    tests = tables["tests"]
    assert set(tests["role"].dropna()) == {"A", "B"}  # the real onepatch analysis wrote the table
    marked = tests.assign(stars=[f"S{i}" for i in range(len(tests))])
    ax = draw("fig5/E", synthetic_results, {**tables, "tests": marked})
    for role, key in (("B", "fig5/E"), ("A", "fig5/F")):
        ax = draw(key, synthetic_results, {**tables, "tests": marked})
        rows = marked[marked["role"] == role].set_index("group")["stars"]
        assert len(rows) == 3  # one row per size class, against the alone control at the same size
        assert sorted(t.get_text() for t in ax.texts) == sorted(rows)  # each class's bracket carries its own row


@pytest.mark.parametrize(("key", "contrast"), [("fig5/I", "mobility"), ("fig5/J", "eod")])
def test_bot_reach_panels_read_their_stars_from_reach_tests(key, contrast, synthetic_results):
    tables = load_tables(PANELS[key], synthetic_results, 2)
    assert set(tables["tests"]["contrast"]) == {"mobility", "eod"}
    marked = tables["tests"].assign(stars=lambda t: "X" + t["contrast"])
    ax = draw(key, synthetic_results, {**tables, "tests": marked})
    assert [t.get_text() for t in ax.texts if t.get_text().startswith("X")] == [f"X{contrast}"]


def test_food_time_course_lines_are_the_table_means(synthetic_results):
    tables = load_tables(PANELS["fig5/H"], synthetic_results, 2)
    ax = draw("fig5/H", synthetic_results, tables)
    course = tables["course"]
    mine = course[(course["condition"] == "A_alone_75") & (course["agent"] == 0)].sort_values("t")
    line = next(line for line in ax.get_lines() if line.get_label() == "A alone, 0.75")
    assert np.allclose(line.get_ydata(), mine["mean_food"])
    assert line.get_linestyle() == "--"  # alone controls dashed, the classes solid
    assert next(line for line in ax.get_lines() if line.get_label() == "A>B").get_linestyle() == "-"
    fps = tables["conditions/onepatch"].set_index("condition").loc["A_alone_75", "fps"]  # the recorded rate
    assert fps == compose(["assay=onepatch"]).env.fps
    assert np.allclose(line.get_xdata(), mine["t"] / fps)


def test_bot_reach_draws_only_the_trained_agent(synthetic_results):
    tables = load_tables(PANELS["fig5/I"], synthetic_results, 2)
    reach = tables["reach"]
    ax = draw("fig5/I", synthetic_results, tables)
    expected = reach.loc[reach["agent"] == 1, "reach_rate"].to_numpy(float)
    assert np.allclose(point_values(ax), np.sort(expected))


def test_biter_panels_read_stars_from_size_tests(synthetic_results):
    tables = load_tables(PANELS["fig5/M"], synthetic_results, 2)
    assert len(tables["events"]) > 1  # the synthetic pairs bite (they need not chase)
    tests = tables["tests"]
    tests = tests.assign(stars=np.where(tests["measure"] == "bite", "XSTARX", tests["stars"]))
    ax = draw("fig5/M", synthetic_results, {**tables, "tests": tests})
    assert any("XSTARX" in t.get_text() for t in ax.texts)
    assert sum(p.get_height() for p in ax.patches) == pytest.approx(len(tables["events"]))
    ax = draw("fig5/N", synthetic_results, {**tables, "tests": tests})
    assert any(t.get_text() == "XSTARX" for t in ax.texts)


def test_bite_rate_bars_are_the_table_rates(synthetic_results):
    tables = load_tables(PANELS["fig5/P"], synthetic_results, 2)
    rate = tables["rate"].set_index("label")["rate"]
    ax = draw("fig5/P", synthetic_results, tables)
    heights = [p.get_height() for p in ax.patches]
    expected = rate.reindex(LABELS).to_numpy(float)
    assert np.allclose(heights, expected[np.isfinite(expected)])  # a label never seen has no bar ...
    unseen = int(np.sum(~np.isfinite(expected)))
    assert sum(t.get_text() == "n/a" for t in ax.texts) == unseen  # ... but says so


#: A run whose one-patch conditions were recorded under overrides: another frame rate, and the roles swapped (agent 0
#: is the intruder B, agent 1 the resident A), so the condition named A_lt_B is, by the recorded sizes, A > B.
OVERRIDDEN = ("env.fps=25", "env.roles=[intruder,resident]")


def with_sizes(conditions: pd.DataFrame, sizes: dict[str, list[float]]) -> pd.DataFrame:
    """A conditions table with the recorded ``env.sizes`` of some conditions changed (as a run overriding them)."""
    import dataclasses

    from efish.config.recorded import recorded_conditions
    from efish.rollout.conditions import conditions_table

    configs = {c: dataclasses.replace(cfg, env=dataclasses.replace(cfg.env, sizes=sizes[c])) if c in sizes else cfg
               for c, cfg in recorded_conditions(conditions).items()}
    return conditions_table(configs)


def test_roles_matched_classes_and_fps_follow_the_recorded_overrides(synthetic_results, recorded):
    overridden = recorded("onepatch", overrides=OVERRIDDEN)
    configs = assay_conditions(overridden, "onepatch")
    assert fig5.onepatch_roles(configs)["A_lt_B"] == {"B": 0, "A": 1}
    matched = fig5.matched_alone(configs)
    assert (matched["B", "A_lt_B"], matched["A", "A_lt_B"]) == ("B_alone_25", "A_alone_75")  # B is 0.25, A 0.75
    assert fig5.class_label("A_lt_B", configs) == "A>B"
    tables = {**load_tables(PANELS["fig5/E"], synthetic_results, 2), **overridden}
    ax = draw("fig5/E", synthetic_results, tables)
    assert [t.get_text() for t in ax.get_xticklabels()] == ["A>B", "B alone\n0.25", "", "A=B", "B alone\n0.5", "",
                                                             "A<B", "B alone\n0.75"]
    food = tables["food"]
    b_in_a_lt_b = food[(food["condition"] == "A_lt_B") & (food["agent"] == 0)]["food_eaten"].to_numpy(float)
    ys = [off[np.abs(off[:, 0]) < 0.4, 1] for c in ax.collections if len(off := c.get_offsets())]
    assert np.array_equal(np.sort(np.concatenate(ys)), np.sort(b_in_a_lt_b))  # B is agent 0 now
    tables = {**load_tables(PANELS["fig5/H"], synthetic_results, 2), **overridden}
    ax = draw("fig5/H", synthetic_results, tables)
    course = tables["course"]
    mine = course[(course["condition"] == "A_alone_75") & (course["agent"] == 0)].sort_values("t")
    line = next(line for line in ax.get_lines() if line.get_label() == "A alone, 0.75")
    assert np.allclose(line.get_xdata(), mine["t"] / 25.0)  # seconds at the recorded 25 fps, not 83


def test_alone_controls_follow_the_recorded_sizes(synthetic_results, recorded):
    """B alone at 0.8 is the control of A<B when the run records B at 0.8 there; labels say the recorded size."""
    conditions = with_sizes(recorded("onepatch")["conditions/onepatch"], {"A_lt_B": [0.25, 0.8], "B_alone_75": [0.8]})
    configs = assay_conditions({"conditions/onepatch": conditions}, "onepatch")
    assert fig5.matched_alone(configs)["B", "A_lt_B"] == "B_alone_75"
    tables = {**load_tables(PANELS["fig5/E"], synthetic_results, 2), "conditions/onepatch": conditions}
    ax = draw("fig5/E", synthetic_results, tables)
    assert [t.get_text() for t in ax.get_xticklabels()][:2] == ["A<B", "B alone\n0.8"]
    scene = draw("fig5/A", synthetic_results, {**load_tables(PANELS["fig5/A"], synthetic_results, 2),
                                               "conditions/onepatch": conditions})
    assert scene.get_title().startswith("One-patch assay (A<B")


def test_a_panel_without_the_conditions_table_says_which_to_rerun(synthetic_results):
    tables = load_tables(PANELS["fig5/E"], synthetic_results, 2)
    del tables["conditions/onepatch"]
    with pytest.raises(ValueError, match=r"no conditions/onepatch \(assays/onepatch/conditions.parquet\)"):
        draw("fig5/E", synthetic_results, tables)


def test_nan_only_table_says_why_on_the_panel():
    nan_row = pd.DataFrame([{"condition": np.nan, "episode": np.nan, "size_difference": np.nan,
                             "reason": "no chasing bout"}])
    tests = pd.DataFrame(columns=["measure", "condition", "group", "stars", "effect"])
    for key in ("fig5/K", "fig5/L"):
        ax = draw(key, None, {"events": nan_row, "tests": tests})
        assert any("no chasing bout" in t.get_text() for t in ax.texts)
