"""The recipe's verdict over the top seeds (efish.claims.recipe), on planted seed effects with known answers."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest
from scipy import stats

from efish.claims.fig3 import excess_w
from efish.claims.recipe import (
    RECIPE_COLUMNS,
    RECIPE_PART_COLUMNS,
    pooled,
    recipe_parts,
    with_recipe_verdicts,
)
from efish.claims.verdicts import PART_COLUMNS, ROW_COLUMNS

ALPHA = 0.05
DELTA = 0.1


def part_table(effects: dict[str, float], verdict: str = "inconclusive", sign: float = 1.0, claim: str = "C9",
               **extra):
    """One seed's claim_parts table: one row per part label with the given effect, decided against ``DELTA``."""
    n = len(effects)
    rows = pd.DataFrame({"claim": claim, "part": list(effects), "statistic": "a test", "sign": sign,
                         "effect": list(effects.values()), "ci_low": np.nan, "ci_high": np.nan, "ci_method": "",
                         "n": 8, "p": 0.2, "family": 1, "p_floor": 0.008, "reference": np.nan, "delta": DELTA,
                         "p_opposite": 1.0, "verdict": verdict, "decides": True, "reason": ""}, index=range(n))
    return rows.assign(**extra)[PART_COLUMNS]


def seeds_of(effects, **kw) -> dict[int, pd.DataFrame]:
    """Seed -> parts table for one part "a" with the seeds' ``effects`` (the first seed is the selected one)."""
    return {seed: part_table({"a": e}, **kw) for seed, e in zip(range(1, len(effects) + 1), effects, strict=True)}


def verdict_of(effects, **kw) -> pd.Series:
    return recipe_parts(seeds_of(effects, **kw), 1, ALPHA).iloc[0]


def test_pooled_is_the_t_interval_over_the_seeds_effects_decided_against_delta():
    y = np.array([0.3, 0.5, 0.2, 0.6, 0.4])
    out = pooled(y, +1, DELTA, ALPHA)
    t = stats.ttest_1samp(y, 0.0)
    low, high = t.confidence_interval(1 - 2 * ALPHA)
    assert out.decision.effect == pytest.approx(y.mean()) and out.p == pytest.approx(t.pvalue)
    assert (out.decision.low, out.decision.high) == (pytest.approx(low), pytest.approx(high))
    assert out.decision.decision == "holds" and out.tau == pytest.approx(y.std(ddof=1))
    bonf = pooled(y, +1, DELTA, ALPHA, family=3)
    assert bonf.p == pytest.approx(min(1.0, 3 * t.pvalue)) and bonf.decision.low < low and bonf.decision.high > high


@pytest.mark.parametrize("effects, sign, expected", [
    ([0.5, 0.45, 0.55, 0.5, 0.6], +1, "holds"),  # the paper's sign beyond delta at every seed
    ([-0.5, -0.45, -0.55, -0.5, -0.6], +1, "opposite"),  # the opposite sign beyond delta at every seed
    ([0.02, -0.03, 0.01, -0.02, 0.01], +1, "absent"),  # none: the interval lies within +-delta
    ([0.6, -0.6, 0.6, -0.6, 0.55], +1, "inconclusive"),  # seeds with opposite effects: no recipe effect
    ([-0.5, -0.45, -0.55, -0.5, -0.6], -1, "holds"),  # the paper's negative sign
])
def test_the_recipe_verdict_follows_the_planted_seed_effects(effects, sign, expected):
    row = verdict_of(effects, sign=sign)
    assert row["verdict"] == expected and row["n"] == 5 and row["delta"] == DELTA
    oriented = (row["ci_low"] * sign, row["ci_high"] * sign)
    assert (min(oriented) > DELTA) == (expected == "holds") and (max(oriented) < -DELTA) == (expected == "opposite")
    assert (row["p_opposite"] < ALPHA) == (expected == "opposite")


@pytest.mark.parametrize("seeds, expected", [(3, "inconclusive"), (60, "absent")])
def test_an_effect_between_zero_and_delta_is_inconclusive_over_few_seeds_and_absent_over_many(seeds, expected):
    """Seeds' effects about half of delta: over 3 seeds the interval straddles delta; over 60 it lies within it."""
    rng = np.random.default_rng(seeds)
    assert verdict_of(0.05 + rng.normal(0, 0.03, seeds))["verdict"] == expected


def test_seeds_with_one_and_the_same_effect_are_a_point_and_their_p_the_sign_test():
    assert pooled([-1.0] * 4, +1, DELTA, ALPHA).p == pytest.approx(0.125)  # t is undefined: 2 / 2^4
    assert pooled([-1.0] * 6, +1, DELTA, ALPHA).p == pytest.approx(0.03125)
    assert pooled([0.0] * 6, +1, DELTA, ALPHA).p == 1.0
    assert verdict_of([-1.0] * 4)["verdict"] == "opposite" and verdict_of([1.0] * 6)["verdict"] == "holds"
    assert verdict_of([0.0] * 6)["verdict"] == "absent"


def test_seeds_that_each_hold_in_opposite_directions_never_make_the_recipe_hold():
    rng = np.random.default_rng(0)
    verdicts = [verdict_of(np.r_[rng.normal(0.8, 0.1, 3), rng.normal(-0.8, 0.1, 2)], verdict="holds")["verdict"]
                for _ in range(50)]
    assert "holds" not in verdicts


def test_with_no_effect_the_recipe_holds_or_is_opposite_at_most_alpha_each_way():
    rng = np.random.default_rng(1)
    verdicts = pd.Series([verdict_of(rng.normal(0.0, 1.0, 4))["verdict"] for _ in range(400)])
    se = 3 * np.sqrt(ALPHA * (1 - ALPHA) / len(verdicts))
    assert (verdicts == "holds").mean() <= ALPHA + se and (verdicts == "opposite").mean() <= ALPHA + se


def test_correlations_combine_on_fishers_z_and_stay_correlations():
    row = verdict_of([0.9, 1.0, 0.95], ci_method="inverts the Fisher-z test")
    z = np.arctanh([0.9, 0.999, 0.95])
    assert row["effect"] == pytest.approx(np.tanh(z.mean())) and -1 < row["ci_low"] < row["ci_high"] < 1
    assert "Fisher-z" in row["ci_method"] and row["verdict"] == "holds"


def test_a_no_difference_part_holds_when_the_seeds_lie_within_delta_and_is_opposite_beyond_it():
    near = verdict_of([0.01, -0.02, 0.0, 0.02, -0.01], sign=0.0, delta=0.5)
    assert near["verdict"] == "holds" and near["delta"] == 0.5
    far = verdict_of([2.0, 2.1, 1.9, 2.05, 1.95], sign=0.0, delta=0.5)
    assert far["verdict"] == "opposite"


def test_a_no_difference_part_whose_delta_the_seeds_cannot_reach_is_not_decidable():
    """Seeds' effects of SD 0.9 about 0 over 4 seeds (SE 0.45): the 0.9 t interval is 2.1 wide, more than twice a
    delta of 0.5, so it could not lie within +-delta whatever the mean: not decidable; a delta of 2 can be shown."""
    spread = [1.0, -1.0, 0.8, -0.9]
    narrow = verdict_of(spread, sign=0.0, delta=0.5)
    assert narrow["verdict"] == "not decidable", narrow["reason"]
    assert verdict_of(spread, sign=0.0, delta=2.0)["verdict"] == "holds"
    assert verdict_of([3.0, 3.2, 2.9, 3.1], sign=0.0, delta=0.5)["verdict"] == "opposite"  # beyond it


def test_seeds_that_cannot_carry_the_part_are_left_out_and_named():
    seeds = seeds_of([0.5, 0.55, 0.45, np.nan])
    seeds[3] = part_table({"a": np.nan}, verdict="not decidable", p_floor=0.0)  # a ceiling: no effect
    seeds[2] = part_table({"a": 0.45}, verdict="not decidable", p_floor=0.25)  # too few episodes: pooled
    seeds[4] = part_table({"a": np.nan}, verdict="not run")
    row = recipe_parts(seeds, 1, ALPHA).iloc[0]
    assert row["n"] == 2 and row["seeds"] == "1, 2, 3, 4"
    assert "left out: seed 3: not decidable; seed 4: not run" in row["reason"]
    alone = recipe_parts({1: part_table({"a": 0.5}), 2: part_table({"a": np.nan}, verdict="not decidable",
                                                                   p_floor=0.0)}, 1, ALPHA).iloc[0]
    assert alone["verdict"] == "not decidable" and alone["n"] == 1
    assert recipe_parts({1: part_table({"a": 0.5})}, 1, ALPHA).iloc[0]["verdict"] == "not run"


def test_a_relative_delta_is_the_median_of_the_seeds_deltas():
    seeds = {s: part_table({"a": 5.0 + 0.1 * s}, delta=d) for s, d in zip(range(1, 5), (1.0, 2.0, 3.0, 9.0),
                                                                         strict=True)}
    assert recipe_parts(seeds, 1, ALPHA).iloc[0]["delta"] == 2.5


def test_a_part_a_seed_lacks_is_not_run_there():
    seeds = {1: part_table({"a": 0.5, "b": 0.5}), 2: part_table({"a": 0.6}), 3: part_table({"a": 0.55, "b": 0.4})}
    out = recipe_parts(seeds, 1, ALPHA).set_index("part")
    assert list(out.columns) == RECIPE_PART_COLUMNS[:1] + RECIPE_PART_COLUMNS[2:]
    assert out.loc["a", "n"] == 3 and out.loc["b", "n"] == 2 and "seed 2: not run" in out.loc["b", "reason"]


def claims_row(claim: str = "C9") -> pd.DataFrame:
    return pd.DataFrame([{"claim": claim, "panel": "3O", "statistic": "x", "effect": 0.5, "ci_low": 0.1,
                          "ci_high": 0.9, "n": 8, "p": 0.01, "verdict": "holds", "parts": "1 holds", "reason": ""}],
                        columns=ROW_COLUMNS)


def test_the_claims_row_combines_the_recipe_parts_like_a_seeds_parts():
    seeds = {s: part_table({"a": 0.5 + 0.02 * s, "b": (-1) ** s * 0.3}) for s in range(1, 6)}
    out = with_recipe_verdicts(claims_row(), recipe_parts(seeds, 1, ALPHA), ALPHA)
    assert list(out.columns) == [*ROW_COLUMNS[:2], *RECIPE_COLUMNS, *ROW_COLUMNS[2:]]
    row = out.iloc[0]
    assert row["recipe_verdict"] == "inconclusive" and row["recipe_seeds"] == 5
    assert row["recipe_parts"] == "1 holds, 1 inconclusive"
    assert row["recipe_effect"] == pytest.approx(0.56) and row["verdict"] == "holds"  # the selected seed's stays


@pytest.mark.parametrize("b, expected", [
    ([0.5, 0.55, 0.45, 0.5, 0.52], "holds"),  # every part beyond delta
    ([-0.5, -0.55, -0.45, -0.5, -0.52], "opposite"),  # part b far beyond delta the other way: Holm confirms it
    ([0.01, -0.01, 0.0, 0.02, -0.02], "inconclusive"),  # a holds, b absent
])
def test_the_recipe_claim_verdict_is_holm_over_its_parts(b, expected):
    """A claim of two parts over 5 seeds: part a holds; part b planted as given. The claim holds when both hold,
    is opposite when b's p of "beyond delta the other way", Holm-adjusted over the two parts, is below alpha."""
    seeds = {s: part_table({"a": 0.5 + 0.02 * s, "b": b[s - 1]}) for s in range(1, 6)}
    recipe = recipe_parts(seeds, 1, ALPHA)
    assert recipe.set_index("part").loc["a", "verdict"] == "holds"
    assert with_recipe_verdicts(claims_row(), recipe, ALPHA).iloc[0]["recipe_verdict"] == expected
    # both parts absent: the claim is absent
    nothing = {s: part_table({"a": b[s - 1] * 0 + 0.01 * (-1) ** s, "b": 0.0}) for s in range(1, 6)}
    assert with_recipe_verdicts(claims_row(), recipe_parts(nothing, 1, ALPHA), ALPHA).iloc[0]["recipe_verdict"] \
        == "absent"


def test_bad_parts_tables_are_one_line_errors():
    with pytest.raises(ValueError, match="selected seed 9 has no claim_parts"):
        recipe_parts(seeds_of([0.1, 0.2]), 9, ALPHA)
    with pytest.raises(ValueError, match="lacks columns"):
        recipe_parts({1: part_table({"a": 0.1}).drop(columns="p_floor"), 2: part_table({"a": 0.2})}, 1, ALPHA)


def test_a_claim_no_other_seed_runs_is_one_draw_not_a_missing_recipe():
    """The homing claims run once (their policies do not depend on the seed): the recipe keeps the selected
    seed's part and says it is one draw; a part another seed ran but this one did not still needs two seeds."""
    seeds = {1: part_table({"a": 0.5}, verdict="holds", claim="C1"), 2: part_table({"a": np.nan}, verdict="not run",
                                                                                  claim="C1")}
    row = recipe_parts(seeds, 1, ALPHA).iloc[0]
    assert row["verdict"] == "holds" and row["n"] == 1 and row["effect"] == 0.5 and "one draw" in row["reason"]



def test_an_any_difference_part_holds_beyond_delta_and_is_absent_below_it():
    """An "any difference" part's effect is an excess over its null expectation (C5's Kendall's W - 1/n), which
    every departure from the null raises: seeds whose excess lies below delta are absent (never opposite), beyond
    it they hold; the p column is the two-sided t-test's."""
    below = verdict_of([-0.10, -0.12, -0.09, -0.11], sign=np.nan)
    assert below["verdict"] == "absent" and below["p_opposite"] == 1.0
    above = verdict_of([0.30, 0.32, 0.29, 0.31], sign=np.nan)
    assert above["verdict"] == "holds" and above["ci_low"] > DELTA
    assert above["p"] == pytest.approx(stats.ttest_1samp([0.30, 0.32, 0.29, 0.31], 0.0).pvalue)


def _c5_recipe_verdicts(rates: np.ndarray) -> np.ndarray:
    """The recipe verdicts of C5's part in simulated runs: ``rates`` [run, seed, episode, bin], each seed's effect
    W - 1/n of its episodes' rates (efish.claims.fig3.excess_w, as C5 computes it), decided over the seeds as
    recipe_parts decides an "any difference" part (:func:`efish.claims.recipe.pooled`, delta 0.1)."""
    effects, _ = excess_w(rates)
    return np.array([pooled(seeds, None, DELTA, ALPHA).decision.decision for seeds in effects])


def test_c5s_recipe_holds_at_most_alpha_without_a_distance_effect_and_mostly_with_one():
    """The third audit: testing the seeds' Kendall's W against 0 held C5 in 67-100% of runs with no distance
    effect, W being never negative. With the seeds' W - 1/n decided against delta 0.1, 1,000 simulated runs of 4
    seeds (the laptop scale's top seeds) at 6 episodes and 8 distance bins, the rates noise, hold at most alpha
    plus three Monte-Carlo standard errors and are never opposite; with a planted distance effect, most hold."""
    rng = np.random.default_rng(5)
    runs, seeds, episodes, bins = 1000, 4, 6, 8
    null = _c5_recipe_verdicts(rng.normal(size=(runs, seeds, episodes, bins)))
    assert set(null) <= {"holds", "absent", "inconclusive"}  # an "any difference" part cannot be opposite
    assert (null == "holds").mean() <= ALPHA + 3 * np.sqrt(ALPHA * (1 - ALPHA) / runs), (null == "holds").mean()
    planted = _c5_recipe_verdicts(rng.normal(size=(runs, seeds, episodes, bins)) + 0.4 * np.arange(bins))
    assert (planted == "holds").mean() > 0.8, (planted == "holds").mean()
    # the same seeds' effects decide so in recipe_parts, from their claim_parts rows
    effects = excess_w(rng.normal(size=(seeds, episodes, bins)) + 0.4 * np.arange(bins))[0]
    row = recipe_parts({s + 1: part_table({"a": e}, sign=np.nan, claim="C5") for s, e in enumerate(effects)}, 1,
                       ALPHA).iloc[0]
    assert row["verdict"] == pooled(effects, None, DELTA, ALPHA).decision.decision == "holds"
    assert row["p"] == pooled(effects, None, DELTA, ALPHA).p
