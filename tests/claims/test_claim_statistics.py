"""The statistics of the revised claim rules, on data with known answers: Holm, TOST, excess Theil, ceilings and
the slope interaction."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest
from scipy import stats as sps

from efish.analysis.inequality import theil_t
from efish.claims.statistics import (
    at_ceiling,
    equivalence_margin,
    excess_theil,
    holm,
    interaction_slope,
    null_theil,
    paired_vs_control,
    tost_paired,
    tost_unpaired,
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


def test_tost_shows_equivalence_of_equal_samples_more_easily_as_n_grows():
    rng = np.random.default_rng(1)
    small = [tost_paired(rng.normal(0, 1, 8), 0.5) for _ in range(20)]
    large = [tost_paired(rng.normal(0, 1, 400), 0.5) for _ in range(20)]
    assert np.median(large) < 0.001 < np.median(small)
    assert tost_paired(rng.normal(2.0, 1, 400), 0.5) > 0.5  # a real difference is never equivalent
    assert tost_unpaired(rng.normal(0, 1, 300), rng.normal(0, 1, 300), 0.5) < 0.01
    assert tost_unpaired(rng.normal(1.5, 1, 300), rng.normal(0, 1, 300), 0.5) > 0.5


def test_equivalence_margin_is_relative_unless_the_control_sits_near_zero():
    assert equivalence_margin(np.full(10, 20.0), 2.0, 0.2, 0.5) == (pytest.approx(4.0), pytest.approx(0.2),
                                                                   "0.2 x control median 20")
    # a median of 0 (mostly-zero counts): 0.5 SD of the differences, within half the typical value (mean 1.2)
    margin, ratio, how = equivalence_margin(np.array([0.0, 0, 0, 2, 4]), 1.0, 0.2, 0.5)
    assert margin == pytest.approx(0.5) and ratio == pytest.approx(0.5 / 1.2) and "SD" in how
    with pytest.raises(ValueError):
        equivalence_margin(np.zeros(4), 0.0, 0.2, 0.5)


def test_no_margin_is_wider_than_half_the_controls_typical_value():
    """The second audit: at seed 4, C14's margin +-12.8 was 107% of the control median 12."""
    control = np.array([10.0, 12, 12, 14, 40])  # median 12, a wide spread (pooled SD ~13)
    margin, ratio, how = equivalence_margin(control, 25.6, 0.2, 0.5)
    # the median 12 is within one SD of 0, so the SD fallback applies: 0.5 x 25.6 = 12.8, capped at 6
    assert margin == pytest.approx(6.0) and ratio == pytest.approx(0.5) and "typical value" in how
    margin, ratio, how = equivalence_margin(np.array([0.0, 0, 0, 2, 4]), 25.6, 0.2, 0.5)  # median 0, mean 1.2
    assert margin == pytest.approx(0.6) and ratio == pytest.approx(0.5) and "typical value" in how
    for sd in (0.1, 1.0, 10.0, 100.0):
        m, r, _ = equivalence_margin(np.array([3.0, 5, 8, 9]), sd, 0.2, 0.5)
        assert 0 < r <= 0.5 and m <= 0.5 * 6.5


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
