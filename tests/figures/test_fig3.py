"""Fig 3 and the supplement's IDI histogram: every panel draws from real-shaped tables, and what it draws is
what the analysis tables hold (bars, lines, heat-map cells, fitted lines, the tests' stars)."""

from __future__ import annotations

from contextlib import contextmanager

import numpy as np
import pandas as pd
import pytest

from efish.analysis.registry import run
from efish.analysis.stats import STAT_COLUMNS
from efish.config import compose
from efish.figures import fig3
from efish.figures.panel import conditions_key
from efish.figures.registry import PANELS
from efish.figures.render import load_tables, render_panel
from efish.figures.style import panel_style

from ..helpers import DEFAULT_FPS, HALF_FPS, cfg_with, planted_rate_tables

KEYS = [p.key for p in fig3.PANELS]


@contextmanager
def drawn(key: str, tables: dict[str, pd.DataFrame]):
    """The axes panel ``key`` drew on from ``tables``; the figure is closed afterwards."""
    with panel_style() as plt:
        fig = plt.figure()
        ax = fig.add_subplot(projection=PANELS[key].projection)
        PANELS[key].draw(tables, ax)
        try:
            yield ax
        finally:
            plt.close(fig)


@pytest.fixture(scope="module")
def tables(synthetic_results):
    """Every fig3 panel's tables from the synthetic results folder, keyed by panel."""
    return {key: load_tables(PANELS[key], synthetic_results, seeds=2) for key in KEYS}


def _texts(ax) -> str:
    return " ".join(t.get_text() for t in ax.texts)


def test_fig3_lists_every_panel_of_spec_13_and_the_supplement_histogram():
    assert KEYS == [f"fig3/{c}" for c in "ABCDEFGHIJKLMNOP"] + ["supp/idi_histogram"]
    assert all(PANELS[k] is p for k, p in zip(KEYS, fig3.PANELS, strict=True))
    assert {a for p in fig3.PANELS for a in p.assays()} == {"patchy4", "wide2"}


@pytest.mark.parametrize("key", KEYS)
def test_panel_renders_with_labelled_axes_or_says_why_not(key, synthetic_results, tables, tmp_path):
    written = render_panel(key, synthetic_results, tmp_path, seeds=2)
    assert [p.suffix for p in written] == [".png", ".pdf"] and all(p.stat().st_size > 1000 for p in written)
    with drawn(key, tables[key]) as ax:
        if _texts(ax).startswith("no data"):
            return
        assert ax.get_xlabel() and ax.get_ylabel() and ax.get_title()


def test_ethogram_bars_are_the_label_fractions(tables):
    labels = tables["fig3/A"]["labels"]
    shown = labels[labels["label"] != "undefined"]  # the synthetic pairs never coincide: no undefined steps
    with drawn("fig3/A", tables["fig3/A"]) as ax:
        heights = [bar.get_height() for bar in ax.patches]
        ticks = [t.get_text() for t in ax.get_xticklabels()]
    assert ticks == shown["label"].tolist()
    np.testing.assert_allclose(heights, 100 * shown["fraction"].to_numpy())


def test_trajectories_follow_the_first_episode(tables):
    steps = tables["fig3/B"]["steps"]
    first = steps[(steps["condition"] == steps["condition"].min()) & (steps["episode"] == 0)].sort_values("t")
    with drawn("fig3/B", tables["fig3/B"]) as ax:
        paths = [line for line in ax.get_lines() if len(line.get_xdata()) > 1]
        limits = ax.get_xlim()
    assert len(paths) == first["agent"].nunique()
    np.testing.assert_allclose(paths[0].get_ydata(), first.loc[first["agent"] == 0, "y_cm"])
    assert limits == (0, compose(["assay=patchy4"]).arena.width_cm)


def test_idi_fractions_of_each_source_sum_to_one(tables):
    with drawn("fig3/C", tables["fig3/C"]) as ax:
        sums = [patch.get_data().values.sum() for patch in ax.patches]
        assert "real fish" in _texts(ax)  # no real-fish table in the synthetic run: said, not drawn
    assert sums and np.allclose(sums, 1.0)


def test_power_law_line_has_the_fitted_exponent(tables):
    fit = tables["fig3/D"]["power_law"].query("source == 'agents'").iloc[0]
    with drawn("fig3/D", tables["fig3/D"]) as ax:
        line = next(line for line in ax.get_lines() if line.get_linestyle() == "--")
        assert f"{fit['R_lognormal']:.2f}" in _texts(ax)
    x, y = line.get_xdata(), line.get_ydata()
    slope = np.log(y[-1] / y[0]) / np.log(x[-1] / x[0])
    assert slope == pytest.approx(1 - fit["alpha"])


def test_rate_vs_agent_distance_draws_the_binned_means(tables):
    rows = tables["fig3/E"]["rate_by_distance"].query("to == 'agent'").sort_values("bin_mid_cm")
    with drawn("fig3/E", tables["fig3/E"]) as ax:
        line = ax.get_lines()[0]
    np.testing.assert_allclose(line.get_xdata(), rows["bin_mid_cm"])
    np.testing.assert_allclose(line.get_ydata(), rows["mean_hz"])


def test_peri_event_curve_is_the_mean_around_the_event(tables):
    rows = tables["fig3/H"]["peri_event"].query("event == 'ate'").sort_values("lag_ms")
    with drawn("fig3/H", tables["fig3/H"]) as ax:
        curve = ax.get_lines()[0]
    np.testing.assert_allclose(curve.get_ydata(), rows["mean_hz"])


def test_bite_heatmap_cells_are_the_bite_fractions(tables):
    matrix = tables["fig3/K"]["bite_matrix"]
    expected = matrix.pivot(index="biter_class", columns="victim_class", values="fraction").sort_index(
        ascending=False)
    with drawn("fig3/K", tables["fig3/K"]) as ax:
        cells = ax.collections[0].get_array().reshape(expected.shape)
        counts = [int(t.get_text()) for t in ax.texts]
    np.testing.assert_allclose(cells, expected.to_numpy())
    assert sum(counts) == matrix["bites"].sum()


def test_food_vs_size_draws_the_tables_fit_and_stars(tables):
    fit = tables["fig3/M"]["food_vs_size"].iloc[0]
    with drawn("fig3/M", tables["fig3/M"]) as ax:
        line = ax.get_lines()[0]
        label = ax.get_legend().get_texts()[0].get_text()
        points = ax.collections[0].get_offsets()
    np.testing.assert_allclose(line.get_ydata(), fit["intercept"] + fit["effect"] * line.get_xdata())
    assert label.endswith(fit["stars"]) and f"{fit['r2']:.2f}" in label
    assert len(points) == len(tables["fig3/M"]["food_per_agent"])


@pytest.mark.parametrize("key, stats, where", [("fig3/L", "size_tests", {"measure": "win_ratio"}),
                                               ("fig3/O", "size_tests", {"measure": "eod_probability"}),
                                               ("fig3/P", "rate_tests", {})])
def test_size_panels_print_the_stars_of_their_test(tables, key, stats, where):
    row = tables[key][stats]
    for column, value in where.items():
        row = row[row[column] == value]
    with drawn(key, tables[key]) as ax:
        text = _texts(ax)
    assert f"rho = {row['effect'].iloc[0]:.2f}" in text and f" {row['stars'].iloc[0]} (n = " in text


def test_eod_rate_is_probability_times_frame_rate(tables):
    probability = tables["fig3/O"]["eod_probability"]["eod_probability"].to_numpy()
    with drawn("fig3/O", tables["fig3/O"]) as ax:
        y = ax.collections[0].get_offsets()[:, 1]
    np.testing.assert_allclose(y, probability * compose(["assay=patchy4"]).env.fps, rtol=1e-6)


def test_rates_and_arena_follow_the_frame_rate_and_arena_the_run_recorded(tables, recorded):
    """A run at 25 fps in a 90 x 80 cm arena: panel O's Hz are probability x 25, panel B's limits that arena."""
    overridden = recorded("patchy4", overrides=("env.fps=25", "arena.width_cm=90", "arena.height_cm=80"))
    probability = tables["fig3/O"]["eod_probability"]["eod_probability"].to_numpy()
    with drawn("fig3/O", {**tables["fig3/O"], **overridden}) as ax:
        y = ax.collections[0].get_offsets()[:, 1]
        top = ax.dataLim.ymax
    np.testing.assert_allclose(y, probability * 25.0, rtol=1e-6)
    assert top == pytest.approx(25.0 * probability.max(), rel=1e-6)
    with drawn("fig3/B", {**tables["fig3/B"], **overridden}) as ax:
        assert (ax.get_xlim(), ax.get_ylim()) == ((0, 90), (0, 80))


def test_rates_are_drawn_in_the_hz_each_condition_recorded():
    """Issue 38: an assay with one condition at half the default env.fps. Agents that discharge on every 5th step
    are drawn at fps / 5 Hz: 16.6 for the default condition, 8.3 for the slow one, on panel E (rate vs distance)
    and panel H (around eating, whose time axis is in each condition's ms); panel O's Hz are each condition's EOD
    probability (0.2) times its own recorded rate."""
    planted, settings = planted_rate_tables(period=5), cfg_with("scale=smoke").analysis
    fps = {"default": DEFAULT_FPS, "slow": HALF_FPS}
    signalling, behaviour = run("signalling", planted, settings), run("behaviour", planted, settings)
    with drawn("fig3/E", {"rate_by_distance": signalling["rate_by_distance"]}) as ax:
        lines = {line.get_label(): line for line in ax.get_lines()}
    with drawn("fig3/H", {"peri_event": signalling["peri_event"]}) as ax:
        curves = {line.get_label(): line for line in ax.get_lines() if line.get_label() in fps}
    reach = {}  # the last lag drawn, in steps
    for condition, rate in fps.items():
        assert lines[condition].get_ydata() == pytest.approx(rate / 5)
        y, x = curves[condition].get_ydata(), curves[condition].get_xdata()
        assert y[np.isfinite(y)] == pytest.approx(rate / 5)
        lags = np.asarray(x, float) * rate / 1000.0
        assert lags == pytest.approx(np.round(lags))  # whole steps of the condition's own duration
        reach[condition] = round(lags.max())
    assert reach["default"] == reach["slow"] > 0
    recorded = {conditions_key("patchy4"): planted["conditions"]}
    with drawn("fig3/O", {"eod_probability": behaviour["eod_probability"], "size_tests": behaviour["size_tests"],
                          **recorded}) as ax:
        drawn_hz = {c.get_label(): np.asarray(c.get_offsets()[:, 1], float) for c in ax.collections}
    assert set(drawn_hz) == set(fps)
    for condition, rate in fps.items():
        assert drawn_hz[condition] == pytest.approx(0.2 * rate)


def test_theil_panel_reads_its_test_when_the_table_holds_one(tables):
    full = tables["fig3/N"]
    base = {**full, "size_tests": full["size_tests"][full["size_tests"]["measure"] != "theil_t"]}
    with drawn("fig3/N", base) as ax:
        assert "no test" in _texts(ax)
    row = pd.DataFrame([dict(zip(STAT_COLUMNS, ["spearman", "control", "size_theil_t", 6, 6, 0.81, "rho", 0.81,
                                                0.049, "*", ""], strict=True))]).assign(measure="theil_t")
    with drawn("fig3/N", {**base, "size_tests": pd.concat([base["size_tests"], row])}) as ax:
        assert "rho = 0.81, p = 0.049 * (n = 6)" in _texts(ax)


@pytest.mark.parametrize("key, table, rows", [("fig3/L", "win_ratio", "index >= 0"),
                                              ("fig3/K", "bite_matrix", "index >= 0"),
                                              ("fig3/I", "peri_event", "event == 'bit'"),
                                              ("fig3/C", "idi_histogram", "index >= 0")])
def test_a_table_of_nan_rows_is_said_with_its_reason(tables, key, table, rows):
    nan = tables[key][table].query(rows).head(1).copy()
    numeric = nan.select_dtypes("number").columns.difference(["bin_lo_ms", "bin_hi_ms"])
    nan[numeric] = np.nan
    nan = nan.assign(reason="nothing happened here", count=0) if table == "idi_histogram" else nan.assign(
        reason="nothing happened here")
    with drawn(key, {**tables[key], table: nan}) as ax:
        text = _texts(ax).replace("\n", " ")
    assert text.startswith("no data") and "nothing happened here" in text
