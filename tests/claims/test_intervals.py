"""Intervals that invert their tests (efish.claims.intervals): they agree with the test's verdict on any data, ties
and zeros included, match the textbook Hodges-Lehmann intervals without ties, and follow Holm's adjustment."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy import stats as sps

from efish.analysis.stats import signed_rank_test
from efish.claims.intervals import (
    holm_alpha,
    rank_sum_interval,
    signed_rank_interval,
    smallest_p_rank_sum,
    smallest_p_signed_rank,
)
from efish.claims.statistics import holm


def contradicts(p: float, low: float, high: float, alpha: float = 0.05) -> bool:
    """A significant test beside an interval with 0 strictly inside, or a non-significant one beside an interval
    that strictly excludes 0."""
    return (p < alpha and low < 0 < high) or (p >= alpha and (low > 0 or high < 0))


@pytest.mark.parametrize("integers", [False, True], ids=["continuous", "counts with ties and zeros"])
def test_the_signed_rank_interval_never_contradicts_its_test(integers):
    rng = np.random.default_rng(3)
    checked = 0
    for _ in range(150):
        d = rng.normal(rng.choice([0.0, 0.6, 1.2]), 1.0, rng.integers(6, 14))
        d = np.round(2 * d) if integers else d
        if not np.any(d):
            continue
        interval = signed_rank_interval(d, 0.05)
        assert interval.low <= interval.estimate <= interval.high
        assert not contradicts(signed_rank_test(d)[1], interval.low, interval.high), (d, interval)
        checked += 1
    assert checked > 100


@pytest.mark.parametrize("integers", [False, True], ids=["continuous", "counts with ties"])
def test_the_rank_sum_interval_never_contradicts_its_test(integers):
    rng = np.random.default_rng(4)
    for _ in range(100):
        nx, ny = rng.integers(4, 12, 2)
        x, y = rng.normal(rng.choice([0.0, 1.0, 2.0]), 1.0, nx), rng.normal(0.0, 1.0, ny)
        x, y = (np.round(x), np.round(y)) if integers else (x, y)
        if np.ptp(np.r_[x, y]) == 0:
            continue
        interval = rank_sum_interval(x, y, 0.05)
        p = sps.mannwhitneyu(x, y, alternative="two-sided").pvalue
        assert not contradicts(p, interval.low, interval.high), (x, y, interval)


def test_without_ties_the_intervals_are_the_hodges_lehmann_order_statistics():
    """n = 10 distinct differences: the exact signed-rank critical value gives the 9th and 47th of the 55 Walsh
    averages (P(T <= 8) = 0.0244 <= 0.025 < P(T <= 9)); m = n = 8: the 14th and 51st of the 64 differences."""
    d = np.array([-1.3, 0.4, 0.9, 1.7, 2.2, 2.8, 3.1, 3.9, 4.4, 5.6])
    walsh = np.sort([(d[i] + d[j]) / 2 for i in range(10) for j in range(i, 10)])
    interval = signed_rank_interval(d, 0.05)
    assert (interval.low, interval.high) == (walsh[8], walsh[46])
    assert interval.estimate == np.median(walsh)
    x = np.array([2.1, 3.4, 3.9, 4.6, 5.2, 5.8, 6.3, 7.7])
    y = np.array([0.6, 1.5, 2.4, 2.9, 3.3, 4.1, 4.8, 5.5])
    diffs = np.sort(np.subtract.outer(x, y).ravel())
    interval = rank_sum_interval(x, y, 0.05)
    assert (interval.low, interval.high) == (diffs[13], diffs[50])


def test_the_interval_is_the_same_on_every_call():
    d = np.random.default_rng(5).normal(0.5, 1.0, 12)
    assert signed_rank_interval(d, 0.05) == signed_rank_interval(d.copy(), 0.05)


def test_a_holm_adjusted_interval_excludes_zero_exactly_when_the_adjusted_p_is_significant():
    rng = np.random.default_rng(6)
    for _ in range(40):
        family = [rng.normal(rng.choice([0.0, 0.8]), 1.0, 12) for _ in range(3)]
        raw = np.array([signed_rank_test(d)[1] for d in family])
        adjusted = holm(raw)
        for d, p_raw, p_adj in zip(family, raw, adjusted, strict=True):
            interval = signed_rank_interval(d, holm_alpha(0.05, p_raw, p_adj))
            assert not contradicts(p_adj, interval.low, interval.high), (p_raw, p_adj, interval)


def test_the_smallest_reachable_p_is_that_of_complete_agreement():
    """Eight differences of one sign: p = 2 / 2^8 (the audit's C10 case: x 5 under Holm is 0.039, x 7 is 0.055)."""
    assert signed_rank_test(np.arange(1.0, 9.0))[1] == pytest.approx(smallest_p_signed_rank(8)) == 2 / 256
    assert smallest_p_signed_rank(5) > 0.05 and smallest_p_signed_rank(6) < 0.05
    x, y = np.arange(5.0) + 10, np.arange(5.0)
    assert sps.mannwhitneyu(x, y).pvalue == pytest.approx(smallest_p_rank_sum(5, 5)) == 2 / math.comb(10, 5)
    assert smallest_p_signed_rank(0) == 1.0 and smallest_p_rank_sum(0, 4) == 1.0


def test_the_fisher_z_interval_of_a_rank_correlation_agrees_with_its_test():
    from efish.claims.intervals import smallest_p_rank_correlation, spearman_fisher_z

    rng = np.random.default_rng(8)
    for _ in range(200):
        n = int(rng.integers(4, 40))
        x = rng.normal(size=n)
        rho = sps.spearmanr(x, rng.choice([0.0, 0.5, 1.0]) * x + rng.normal(size=n)).statistic
        p, interval = spearman_fisher_z(rho, n, 0.05)
        assert interval.low <= rho <= interval.high and not contradicts(p, interval.low, interval.high)
    # a larger sample narrows the interval; too few units cannot be tested; 4 pairs cannot reach p < 0.05 exactly
    assert np.ptp(spearman_fisher_z(0.5, 100, 0.05)[1][1:]) < np.ptp(spearman_fisher_z(0.5, 20, 0.05)[1][1:])
    with pytest.raises(ValueError):
        spearman_fisher_z(0.5, 3, 0.05)
    assert smallest_p_rank_correlation(4) > 0.05 > smallest_p_rank_correlation(5)
