"""The claims along training (efish.claims.stages): stages stacked in the claims' order with their env steps;
a planted trend toward the paper's sign, away from it, none, a "no difference" part shrinking, too few stages; the
weighted slope and its dispersion; the one-line summaries and claims.md's "Along training" section."""

from __future__ import annotations

import itertools

import numpy as np
import pandas as pd
import pytest
from scipy import stats as sps

from efish.claims.report import claims_markdown
from efish.claims.stages import (
    STAGE_COLUMNS,
    TREND_COLUMNS,
    TRENDS,
    claims_by_stage,
    stage_trends,
    trend_lines,
    wls_slope,
)
from efish.claims.verdicts import PART_COLUMNS

TOWARD, STABLE, AWAY, UNDECIDED = TRENDS
STEPS = {1: 25_000, 2: 50_000, 3: 75_000, 4: 100_000}


def stage_parts(parts: dict[tuple[str, str], tuple[float | None, list[float]]], half: float = 0.02,
                verdict: str = "holds") -> dict[int, pd.DataFrame]:
    """Parts tables (PART_COLUMNS) per stage 1..K: ``parts`` maps (claim, part) to (the paper's sign, the effect at
    each stage); every interval is effect +- ``half`` (NaN effect: a part that did not run, no interval)."""
    stages = len(next(iter(parts.values()))[1])
    out = {}
    for k in range(stages):
        rows = []
        for (claim, part), (sign, effects) in parts.items():
            e = effects[k]
            rows.append({"claim": claim, "part": part, "statistic": "a statistic",
                         "sign": np.nan if sign is None else float(sign), "effect": e, "ci_low": e - half,
                         "ci_high": e + half, "n": 20, "p": 0.01 if np.isfinite(e) else np.nan,
                         "verdict": verdict if np.isfinite(e) else "not run", "decides": True, "reason": ""})
        out[k + 1] = pd.DataFrame(rows, columns=PART_COLUMNS)
    return out


def trends_of(parts, half: float = 0.02, steps=STEPS) -> pd.DataFrame:
    tables = stage_parts(parts, half)
    return stage_trends(claims_by_stage(tables, {k: steps[k] for k in tables})).set_index(["claim", "part"])


# ------------------------------------------------------------------ stacking
def test_stages_stack_in_the_claims_order_with_env_steps_and_episodes():
    tables = stage_parts({("C10", "food"): (+1, [1, 2, 3, 4]), ("C2", "aligned"): (+1, [1, 2, 3, 4]),
                          ("C10", "EOD"): (-1, [1, 2, 3, 4])})
    stacked = claims_by_stage(tables, STEPS, {1: 4, 2: 8, 3: 8, 4: 8})
    assert list(stacked.columns) == [*STAGE_COLUMNS, "episodes"]
    assert stacked[["claim", "part"]].to_numpy()[::4].tolist() == [["C2", "aligned"], ["C10", "food"], ["C10", "EOD"]]
    assert stacked["stage"].tolist()[:4] == [1, 2, 3, 4]
    assert stacked["env_steps"].tolist()[:4] == list(STEPS.values())
    assert stacked["episodes"].tolist()[:4] == [4, 8, 8, 8]
    assert "episodes" not in claims_by_stage(tables, STEPS).columns


@pytest.mark.parametrize("env_steps, episodes, message", [
    ({1: 1, 2: 2, 3: 3}, None, "no env steps for stages [4]"),
    ({**STEPS, 5: 9}, None, "env steps for stages [5], which have no parts table"),
    ({**STEPS, 3: 10}, None, "must be positive and grow with the stage"),
    (STEPS, {1: 4}, "no episodes for stages [2, 3, 4]"),
])
def test_stacking_refuses_stages_that_do_not_match(env_steps, episodes, message):
    with pytest.raises(ValueError, match=message.replace("[", r"\[").replace("]", r"\]")):
        claims_by_stage(stage_parts({("C3", "a"): (-1, [1, 2, 3, 4])}), env_steps, episodes)


def test_stacking_names_a_table_that_is_no_parts_table():
    tables = stage_parts({("C3", "a"): (-1, [1, 2, 3, 4])})
    tables[2] = tables[2].drop(columns="sign")
    with pytest.raises(ValueError, match="stage 2's table has no column sign"):
        claims_by_stage(tables, STEPS)


# ------------------------------------------------------------------ trends
def test_planted_trends_are_found():
    trends = trends_of({
        ("C3", "growing in the paper's sign"): (-1, [-0.1, -0.2, -0.3, -0.4]),
        ("C7", "growing, paper +"): (+1, [0.05, 0.2, 0.3, 0.45]),
        ("C8", "shrinking toward 0"): (+1, [0.5, 0.4, 0.25, 0.1]),
        ("C9", "flat"): (+1, [0.3, 0.31, 0.29, 0.3]),
        ("C10", "K off (no difference)"): (0, [1.5, 0.9, 0.4, 0.05]),
        ("C11", "no difference, growing apart"): (0, [-0.1, -0.3, -0.6, -0.9]),
        ("C5", "any difference, growing"): (None, [0.02, 0.1, 0.2, 0.3]),
    })
    assert list(trends.columns) == TREND_COLUMNS[2:]
    trend = trends["trend"].to_dict()
    assert trend[("C3", "growing in the paper's sign")] == TOWARD
    assert trend[("C7", "growing, paper +")] == TOWARD
    assert trend[("C8", "shrinking toward 0")] == AWAY
    assert trend[("C9", "flat")] == STABLE
    assert trend[("C10", "K off (no difference)")] == TOWARD  # |effect| shrinks
    assert trend[("C11", "no difference, growing apart")] == AWAY
    assert trend[("C5", "any difference, growing")] == TOWARD
    grow = trends.loc[("C7", "growing, paper +")]
    assert grow["slope_ci_low"] > 0 and grow["p"] < 0.05 and grow["n_stages"] == 4
    assert grow["test"] == "WLS slope of effect on log10 env steps"
    assert trends.loc[("C10", "K off (no difference)"), "test"] == "WLS slope of |effect| on log10 env steps"
    flat = trends.loc[("C9", "flat")]
    assert flat["slope_ci_low"] < 0 < flat["slope_ci_high"] and flat["p"] > 0.05


def test_wide_intervals_make_a_real_change_stable():
    """The same rise with intervals ten times as wide: the slope's interval covers 0."""
    rise = {("C7", "rise"): (+1, [0.1, 0.15, 0.2, 0.25])}
    assert trends_of(rise, half=0.02).loc[("C7", "rise"), "trend"] == TOWARD
    assert trends_of(rise, half=0.5).loc[("C7", "rise"), "trend"] == STABLE


@pytest.mark.parametrize("effects", [[0.1, 0.2], [0.1, np.nan, 0.3, np.nan]])
def test_fewer_than_three_stages_with_an_effect_are_not_decidable(effects):
    steps = {k + 1: STEPS[k + 1] for k in range(len(effects))}
    row = trends_of({("C7", "part"): (+1, effects)}, steps=steps).loc[("C7", "part")]
    assert row["trend"] == UNDECIDED and np.isnan(row["slope"]) and row["n_stages"] == 2
    assert "a trend needs 3" in row["reason"]


def test_a_stage_without_an_interval_does_not_count():
    tables = stage_parts({("C7", "part"): (+1, [0.1, 0.2, 0.3, 0.4])})
    for k in (1, 2):
        tables[k]["ci_high"] = tables[k]["ci_low"]  # an empty interval: no measure of its error
    row = stage_trends(claims_by_stage(tables, STEPS)).iloc[0]
    assert row["trend"] == UNDECIDED and row["n_stages"] == 2


def test_the_weighted_slope_is_numpys_and_scatter_widens_its_interval():
    x, y, se = np.log10([25e3, 5e4, 75e3, 1e5]), np.array([0.1, 0.3, 0.2, 0.5]), np.array([0.1, 0.05, 0.2, 0.1])
    b, s, factor = wls_slope(x, y, se)
    assert b == pytest.approx(np.polyfit(x, y, 1, w=1 / se)[0])  # polyfit weights multiply the residuals
    assert factor >= 1 and s == pytest.approx(factor / np.sqrt(np.sum((x - np.average(x, weights=se ** -2)) ** 2
                                                                     / se ** 2)))
    _, s_tight, factor_tight = wls_slope(x, y, se * 100)  # the same points, intervals far wider than the scatter
    assert factor_tight == 1.0 and s_tight > s


def test_a_rank_test_could_not_see_a_trend_at_four_stages():
    """Why the trend is a weighted slope: a perfectly monotone 4-stage sequence has an exact two-sided Spearman p of
    2/24 = 0.083 (two of the 4! orders are as extreme), while the weighted slope sees it."""
    rhos = [sps.spearmanr([1, 2, 3, 4], order).statistic for order in itertools.permutations([1, 2, 3, 4])]
    assert np.mean(np.abs(rhos) >= 1 - 1e-12) == pytest.approx(0.083, abs=1e-3)
    assert trends_of({("C7", "p"): (+1, [0.1, 0.2, 0.3, 0.4])}).iloc[0]["p"] < 0.05


# ------------------------------------------------------------------ lines and claims.md
def test_trend_lines_say_each_claims_trend_in_one_line():
    trends = stage_trends(claims_by_stage(stage_parts({
        ("C3", "alignment"): (-1, [-0.1, -0.2, -0.3, -0.4]),
        ("C5", "agent"): (None, [0.1, 0.1, 0.1, 0.1]),
        ("C5", "food"): (None, [np.nan, np.nan, 0.1, 0.2])}), STEPS))
    lines = trend_lines(trends)
    assert list(lines) == ["C3", "C5"]
    assert lines["C3"].startswith("C3 (alignment): moving toward the paper's sign (WLS slope of effect on log10 env "
                                  "steps -")
    assert "], p " in lines["C3"] and "\n" not in lines["C3"]
    assert lines["C5"].startswith("C5: agent: stable (WLS slope of |effect|")
    assert "; food: not decidable (2 of 4 stages have a finite effect" in lines["C5"]
    with pytest.raises(ValueError, match="is it claims_trends.parquet"):
        trend_lines(trends.drop(columns="test"))


def test_claims_md_carries_the_trend_lines_in_an_along_training_section():
    table = pd.DataFrame([{"claim": "C3", "panel": "2D", "statistic": "s", "effect": -0.4, "ci_low": -0.5,
                           "ci_high": -0.3, "n": 10, "p": 0.01, "verdict": "holds", "reason": ""}])
    page = claims_markdown(table, "header", {"C3": "C3 (alignment): stable (...)"})
    assert page.startswith("header\n") and "\n## Along training\n" in page
    assert page.rstrip().endswith("- C3 (alignment): stable (...)")
    assert "Along training" not in claims_markdown(table, "header")
