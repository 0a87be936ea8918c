"""The statistics of the revised claim rules, on data with known answers: Holm, Welch's interval, excess Theil, ceilings and
the slope interaction."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest
from scipy import stats as sps

from efish.analysis.inequality import theil_t
from efish.claims.statistics import (
    at_ceiling,
    excess_theil,
    holm,
    interaction_slope,
    null_theil,
    paired_vs_control,
    welch_difference,
)


def test_holm_matches_the_step_down_definition_and_skips_nan():
    p = np.array([0.04, np.nan, 0.001, 0.03])
    adj = holm(p)
    assert np.isnan(adj[1])
    # sorted 0.001, 0.03, 0.04 with multipliers 3, 2, 1, made monotone
    np.testing.assert_allclose(adj[[2, 3, 0]], [0.003, 0.06, 0.06])
    assert np.all(adj[~np.isnan(p)] >= p[~np.isnan(p)])


def test_paired_test_finds_a_small_shift_that_episode_variance_hides_from_an_unpaired_one():
    rng = np.random.default_rng(0)
    base = rng.normal(50, 10, 20)  # episodes differ a lot; the condition shifts each one by -1
    summary = pd.DataFrame({"condition": ["control"] * 20 + ["treated"] * 20, "episode": np.tile(np.arange(20), 2),
                            "food": np.r_[base, base - 1 + rng.normal(0, .3, 20)]})
    paired = paired_vs_control(summary, "food", "control").iloc[0]
    unpaired = sps.mannwhitneyu(base - 1, base).pvalue
    assert paired["p"] < 1e-3 and unpaired > 0.5 and paired["effect"] < 0


def test_welch_difference_inverts_its_test_at_the_level_asked():
    """C13's excess Theil T: the Welch interval at 0.9 excludes 0 exactly when the two-sided p is below 0.1."""
    rng = np.random.default_rng(3)
    for shift in (0.0, 0.3, 0.8):
        x, c = rng.normal(shift, 1, 20), rng.normal(0, 1, 25)
        diff, p, (low, high) = welch_difference(x, c, 0.9)
        assert diff == pytest.approx(x.mean() - c.mean()) and low < diff < high
        assert (low > 0 or high < 0) == (p < 0.1)


def test_excess_theil_is_zero_on_average_for_equal_shares_at_any_total():
    rng = np.random.default_rng(2)
    for total in (8, 20, 80):
        raw = [theil_t(rng.multinomial(total, np.full(4, 0.25))) for _ in range(3000)]
        excess = [excess_theil(rng.multinomial(total, np.full(4, 0.25))) for _ in range(3000)]
        assert abs(np.mean(excess)) < 0.01 and np.mean(raw) > 0.01
    # raw Theil falls with the total by chance alone (about (n - 1) / 2F)
    assert null_theil(8, 4) > null_theil(80, 4) and null_theil(80, 4) == pytest.approx(3 / 160, rel=0.2)
    assert np.isnan(excess_theil([0, 0, 0]))


def test_a_condition_that_eats_every_pellet_is_at_a_ceiling():
    summary = pd.DataFrame({"condition": ["c"] * 4 + ["t"] * 4, "episode": np.tile(np.arange(4), 2),
                            "food_total": [6, 6, 6, 5, 3, 4, 2, 6], "food_offered": 6})
    full, how = at_ceiling(summary, "c", 0.5)
    assert full and "75%" in how
    assert not at_ceiling(summary, "t", 0.5)[0]
    with pytest.raises(ValueError, match="no food_offered column: rerun the behaviour analysis"):
        at_ceiling(summary.drop(columns="food_offered"), "c", 0.5)


def test_interaction_slope_recovers_the_difference_of_slopes():
    rng = np.random.default_rng(3)
    x = np.tile(np.arange(1, 5.0), 30)
    on = np.repeat([0.0, 1.0], 60)
    y = 3 + np.where(on == 1, 2.0, 0.5) * x + rng.normal(0, 0.5, x.size)
    b, p, n, (low, high) = interaction_slope(x, y, on)
    assert low < b < high and (low > 0) == (p < 0.05)
    assert b == pytest.approx(1.5, abs=0.2) and p < 1e-6 and n == 120
    flat = 3 + 1.0 * x + rng.normal(0, 0.5, x.size)
    assert interaction_slope(x, flat, on)[1] > 0.01
    with pytest.raises(ValueError):
        interaction_slope(np.ones(10), np.arange(10.0), np.r_[np.zeros(5), np.ones(5)])
