"""Intervals that agree with their tests: the shifts a rank test does not reject, and the smallest p it can give.

A percentile bootstrap of a median at 8 episodes can exclude 0 beside a test
that is not significant, and the other way round (the second audit found 7 of
50 decided parts so); its endpoints also move with the resampling seed. The
interval beside a rank test here is instead the set of shifts ``delta`` the
test itself does not reject at the part's alpha (the test inverted): for the
signed-rank test of differences ``d``, the ``delta`` whose test of
``d - delta`` gives p >= alpha; for the Mann-Whitney test of ``x`` against
``y``, the ``delta`` whose test of ``x - delta`` against ``y`` does. Without ties
these are the Hodges-Lehmann intervals (order statistics of the Walsh averages,
of the pairwise differences), centred on the Hodges-Lehmann estimate (their
median); computing them by calling the same test makes them agree with the
test with ties and zeros too. The p of a test is constant between the
candidate shifts (the Walsh averages, the pairwise differences), so the test
is evaluated once per gap and once per candidate, outwards from the estimate
until it rejects: the interval is the connected set of shifts around the
estimate that the test does not reject. (With zero differences a shift of
exactly 0 drops them, so the test at 0 can reject while shifts on either
side do not; the interval then stops at 0, as its test does.) No resampling:
the same data give the same interval.

An interval is the closure of the shifts not rejected: an endpoint may itself
be a rejected shift (a test at exactly that shift drops its zero
differences), so an interval *contradicts* its test only when 0 lies strictly
inside it beside a significant p, or strictly outside it beside a
non-significant one.

Where the part's p is Holm-adjusted, the interval is taken at the level at
which Holm's procedure tests that comparison (:func:`holm_alpha`), so it is
adjusted exactly as its p is.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from typing import NamedTuple

import numpy as np
from scipy import stats as sps

from ..analysis.stats import signed_rank_test


class Interval(NamedTuple):
    """A test's estimate of the shift and the shifts it does not reject (-inf / inf where every shift beyond the
    data is accepted, e.g. too few units to reject anything)."""

    estimate: float
    low: float
    high: float


def _inverted(p_of: Callable[[float], float], candidates: np.ndarray, estimate: float, alpha: float) -> Interval:
    """The closure of the shifts whose ``p_of`` is >= ``alpha``, searched among the gaps between the sorted
    unique ``candidates`` (where the test's p is constant) and the candidates themselves."""
    w = np.unique(candidates)
    # positions 0, 2, .., 2K are the gaps (below w[0], between neighbours, above w[-1]); 1, 3, .. the candidates
    def shift(pos: int) -> float:
        if pos % 2:
            return float(w[pos // 2])
        j = pos // 2
        if j == 0:
            return float(w[0] - 1.0)
        return float(w[-1] + 1.0) if j == len(w) else float((w[j - 1] + w[j]) / 2)

    def accepted(pos: int) -> bool:
        return p_of(shift(pos)) >= alpha

    def bound(pos: int, side: int) -> float:
        """The interval's end on ``side`` (-1 low, +1 high) when ``pos`` is its outermost accepted position."""
        if pos % 2:
            return float(w[pos // 2])
        j = pos // 2
        if side < 0:
            return -np.inf if j == 0 else float(w[j - 1])
        return np.inf if j == len(w) else float(w[j])

    last = 2 * len(w)
    centre = int(np.searchsorted(w, estimate)) * 2 + (1 if estimate in w else 0)
    if not accepted(centre):
        return Interval(estimate, np.nan, np.nan)  # the test rejects its own estimate: no interval to report
    low = centre
    while low > 0 and accepted(low - 1):
        low -= 1
    high = centre
    while high < last and accepted(high + 1):
        high += 1
    return Interval(estimate, bound(low, -1), bound(high, +1))


def walsh_averages(d: np.ndarray) -> np.ndarray:
    """(d_i + d_j) / 2 for every i <= j: the shifts at which the signed-rank statistic changes."""
    i, j = np.triu_indices(d.size)
    return (d[i] + d[j]) / 2


def signed_rank_interval(d, alpha: float) -> Interval:
    """The Hodges-Lehmann estimate (median of the Walsh averages) of the differences ``d`` and the shifts the
    two-sided signed-rank test (:func:`efish.analysis.stats.signed_rank_test`) does not reject at ``alpha``.

    >>> signed_rank_interval(np.arange(1.0, 9.0), 0.05)
    Interval(estimate=4.5, low=2.0, high=7.0)
    """
    d = np.asarray(d, np.float64)
    d = d[np.isfinite(d)]
    if d.size == 0:
        raise ValueError("no finite difference for an interval")
    walsh = walsh_averages(d)

    def p_of(delta: float) -> float:
        shifted = d - delta
        return 1.0 if not np.any(shifted) else signed_rank_test(shifted, "two-sided")[1]
    return _inverted(p_of, walsh, float(np.median(walsh)), alpha)


def rank_sum_interval(x, y, alpha: float) -> Interval:
    """The Hodges-Lehmann shift of ``x`` against ``y`` (median of the pairwise differences x_i - y_j) and the
    shifts the two-sided Mann-Whitney test (``scipy.stats.mannwhitneyu``, as
    :func:`efish.analysis.stats.mann_whitney`) does not reject at ``alpha``."""
    x, y = (np.asarray(v, np.float64) for v in (x, y))
    x, y = x[np.isfinite(x)], y[np.isfinite(y)]
    if x.size == 0 or y.size == 0:
        raise ValueError("an empty sample for an interval")
    pairs = np.subtract.outer(x, y).ravel()

    def p_of(delta: float) -> float:
        shifted = x - delta
        if np.ptp(np.r_[shifted, y]) == 0:
            return 1.0
        return float(sps.mannwhitneyu(shifted, y, alternative="two-sided").pvalue)
    return _inverted(p_of, pairs, float(np.median(pairs)), alpha)


def holm_alpha(alpha: float, p_raw: float, p_adjusted: float) -> float:
    """The level at which Holm's procedure tests one comparison: the raw p is below it exactly when the adjusted
    p is below ``alpha`` (alpha x p_raw / p_adjusted; ``alpha`` when there is nothing to adjust).

    >>> round(holm_alpha(0.05, 0.01, 0.03), 4)
    0.0167
    """
    if not (np.isfinite(p_raw) and np.isfinite(p_adjusted)) or p_adjusted <= 0 or p_raw <= 0:
        return alpha
    return alpha * p_raw / p_adjusted


def smallest_p_signed_rank(n: int, sides: int = 2) -> float:
    """The smallest p the exact signed-rank test can give with ``n`` non-zero differences: every sign alike,
    one of 2^n equally likely sign patterns (two of them for a two-sided test)."""
    return min(1.0, sides / 2.0 ** n) if n > 0 else 1.0


def smallest_p_rank_sum(n_x: int, n_y: int, sides: int = 2) -> float:
    """The smallest p the exact Mann-Whitney test can give for samples of ``n_x`` and ``n_y``: complete separation,
    one of C(n_x + n_y, n_x) equally likely orderings (two for a two-sided test)."""
    if n_x < 1 or n_y < 1:
        return 1.0
    return min(1.0, sides / math.comb(n_x + n_y, n_x))


def spearman_fisher_z(rho: float, n: int, alpha: float) -> tuple[float, Interval]:
    """The two-sided p of Spearman's rho against 0 and the interval that inverts the same test: Fisher's z =
    atanh(rho) with Bonett and Wright's standard error sqrt((1 + rho^2 / 2) / (n - 3)) for a rank correlation
    (Psychometrika 65, 2000), so the interval excludes 0 exactly when p < alpha. ValueError below 4 units.

    >>> p, iv = spearman_fisher_z(0.6, 30, 0.05); round(p, 4), round(iv.low, 3), round(iv.high, 3)
    (0.0009, 0.276, 0.802)
    """
    if n < 4:
        raise ValueError(f"{n} units: a Fisher-z test of a correlation needs at least 4")
    r = float(np.clip(rho, -1 + 1e-12, 1 - 1e-12))  # |rho| = 1 is a finite, very large z
    z, se = np.arctanh(r), np.sqrt((1 + r * r / 2) / (n - 3))
    crit = sps.norm.ppf(1 - alpha / 2)
    p = float(2 * sps.norm.sf(abs(z) / se))
    low, high = float(np.tanh(z - crit * se)), float(np.tanh(z + crit * se))
    return p, Interval(float(rho), min(low, float(rho)), max(high, float(rho)))  # |rho| = 1 is its own bound


def smallest_p_rank_correlation(n: int) -> float:
    """The smallest two-sided p an exact permutation test of a rank correlation can give with ``n`` distinct
    pairs: the observed order or its reverse, 2 of n! orders (a normal approximation can claim less at tiny n)."""
    return min(1.0, 2 / math.factorial(n)) if n > 0 else 1.0
