"""Statistical tests as tidy rows (docs/methods/analyses.md): Dunnett vs control, Mann-Whitney, Wilcoxon, Spearman,
Fisher.

Every function returns one row per comparison with the columns of
``STAT_COLUMNS``: which ``test``, the ``group`` and the ``control`` it is
compared with, ``n`` and ``n_control``, an ``effect`` in the value's units
(``effect_kind`` says which), the test ``statistic``, ``p``, ``stars`` and a
``reason`` that is empty unless the row is NaN. A figure or a claim reads the
row; it never recomputes the test. The tests themselves are scipy's; :func:`signed_rank_test` counts one
branch of scipy's Wilcoxon test exactly instead of enumerating it, with the same result.
"""

from __future__ import annotations

import warnings

import numpy as np
import pandas as pd
from scipy import stats as sps

from ._tables import require

STAT_COLUMNS = ["test", "group", "control", "n", "n_control", "effect", "effect_kind", "statistic", "p", "stars",
                "reason"]
#: (threshold, stars), the p <= threshold convention of GraphPad Prism and statannotations.
STAR_LEVELS = ((1e-4, "****"), (1e-3, "***"), (1e-2, "**"), (5e-2, "*"))


def stars(p: float) -> str:
    """Significance stars: ``****`` p <= 1e-4, ``***`` <= 1e-3, ``**`` <= .01, ``*`` <= .05, else ``ns``; NaN ``n/a``.

    >>> [stars(p) for p in (0.2, 0.05, 0.01, 1e-3, 1e-4, float("nan"))]
    ['ns', '*', '**', '***', '****', 'n/a']
    """
    if not np.isfinite(p):
        return "n/a"
    return next((s for level, s in STAR_LEVELS if p <= level), "ns")


def _row(test: str, group, control, n: int, n_control: int, effect: float, effect_kind: str,
         statistic: float = np.nan, p: float = np.nan, reason: str = "") -> dict:
    return {"test": test, "group": group, "control": control, "n": int(n), "n_control": int(n_control),
            "effect": float(effect), "effect_kind": effect_kind, "statistic": float(statistic), "p": float(p),
            "stars": stars(float(p)), "reason": reason}


def _finite(values) -> np.ndarray:
    v = np.asarray(values, dtype=np.float64)
    return v[np.isfinite(v)]


def _samples(df: pd.DataFrame, value: str, group: str, control) -> dict:
    """Finite values per group, the control first; ValueError if the control is missing."""
    if control not in set(df[group]):
        raise ValueError(f"control {control!r} is not a value of column {group!r}")
    # every group is listed, even one without a finite value: its row then says so
    samples = {g: _finite(s[value]) for g, s in df.groupby(group, sort=True)}
    return {control: samples.pop(control), **samples}


def _single_nan_row(test: str, control, effect_kind: str, reason: str) -> pd.DataFrame:
    """The whole answer when there is nothing to compare: one NaN row that says why."""
    return pd.DataFrame([_row(test, np.nan, control, 0, 0, np.nan, effect_kind, reason=reason)], columns=STAT_COLUMNS)


def nan_stat_row(reason: str, **keys) -> pd.DataFrame:
    """One statistic row of NaNs (n = 0, stars ``n/a``) that says why there is no test, plus the ``keys`` columns
    (e.g. ``measure``): what an analysis writes for a test its assay cannot run."""
    return pd.DataFrame([{**{c: np.nan for c in STAT_COLUMNS}, "n": 0, "n_control": 0, "stars": "n/a",
                          "reason": reason, **keys}])


def _too_small(sizes: dict, minimum: int = 2) -> str:
    small = [g for g, n in sizes.items() if n < minimum]
    return f"fewer than {minimum} finite values in group(s) {small}" if small else ""


def dunnett_vs_control(df: pd.DataFrame, value: str, group: str, control, rng: int = 0) -> pd.DataFrame:
    """Dunnett's many-to-one test of every group's mean ``value`` against ``control`` (scipy.stats.dunnett).

    The effect is the difference of means (group minus control). ``rng`` seeds
    scipy's quasi-Monte Carlo p-values so a rerun gives the same p. All rows
    are NaN with a reason when a group has fewer than two values or no group varies.
    """
    require(df, [value, group], "table")
    if df.empty:
        return _single_nan_row("dunnett", control, "mean difference", "empty table")
    samples = _samples(df, value, group, control)
    ctrl, others = samples.pop(control), samples
    if not others:
        return _single_nan_row("dunnett", control, "mean difference", "no group besides the control")
    reason = _too_small({control: ctrl.size, **{g: s.size for g, s in others.items()}})
    if not reason and all(np.ptp(s) == 0 for s in (ctrl, *others.values())):
        reason = "no within-group variance"
    diffs = {g: (s.mean() - ctrl.mean() if s.size and ctrl.size else np.nan) for g, s in others.items()}
    if reason:
        return pd.DataFrame([_row("dunnett", g, control, s.size, ctrl.size, diffs[g], "mean difference",
                                  reason=reason) for g, s in others.items()], columns=STAT_COLUMNS)
    with warnings.catch_warnings():
        # scipy checks each sample's variance for cancellation and flags an exactly constant
        # sample with a non-zero mean; Dunnett uses the pooled variance, which is exact here.
        warnings.filterwarnings("ignore", message="Precision loss occurred", category=RuntimeWarning)
        res = sps.dunnett(*others.values(), control=ctrl, rng=np.random.default_rng(rng))
    return pd.DataFrame([_row("dunnett", g, control, s.size, ctrl.size, diffs[g], "mean difference",
                              res.statistic[i], res.pvalue[i]) for i, (g, s) in enumerate(others.items())],
                        columns=STAT_COLUMNS)


def dunnett_by_measure(df: pd.DataFrame, values: list[str], group: str, control, rng: int = 0) -> pd.DataFrame:
    """:func:`dunnett_vs_control` of each column in ``values``, stacked, with a ``measure`` column naming it."""
    return pd.concat([dunnett_vs_control(df, v, group, control, rng).assign(measure=v) for v in values],
                     ignore_index=True)


def mann_whitney(df: pd.DataFrame, value: str, group: str, control) -> pd.DataFrame:
    """Two-sided Mann-Whitney U test of every group against ``control`` (scipy.stats.mannwhitneyu).

    The effect is the difference of medians (group minus control); the
    statistic is U of the group. No correction for multiple comparisons.
    """
    require(df, [value, group], "table")
    if df.empty:
        return _single_nan_row("mann-whitney", control, "median difference", "empty table")
    samples = _samples(df, value, group, control)
    ctrl = samples.pop(control)
    if not samples:
        return _single_nan_row("mann-whitney", control, "median difference", "no group besides the control")
    rows = []
    for g, s in samples.items():
        effect = np.median(s) - np.median(ctrl) if s.size and ctrl.size else np.nan
        reason = _too_small({control: ctrl.size, g: s.size}, 1)
        if not reason and np.ptp(np.r_[s, ctrl]) == 0:
            reason = "all values identical"
        if reason:
            rows.append(_row("mann-whitney", g, control, s.size, ctrl.size, effect, "median difference",
                             reason=reason))
            continue
        res = sps.mannwhitneyu(s, ctrl, alternative="two-sided")
        rows.append(_row("mann-whitney", g, control, s.size, ctrl.size, effect, "median difference",
                         res.statistic, res.pvalue))
    return pd.DataFrame(rows, columns=STAT_COLUMNS)


#: scipy.stats.wilcoxon (method "auto") tests up to this many differences with ties or zeros by a permutation
#: test over every sign flip; more of them it tests by the normal approximation.
PERMUTATION_MAX_N = 13


def signed_rank_test(d, alternative: str = "two-sided") -> tuple[float, float]:
    """Wilcoxon signed-rank test of the paired differences ``d`` against zero: the statistic and p of
    ``scipy.stats.wilcoxon(d, alternative=alternative)`` (zero_method "wilcox", method "auto"), equal to them.

    Why not scipy's alone: for at most :data:`PERMUTATION_MAX_N` differences with ties or zeros scipy runs a
    permutation test that recomputes the rank sum for each of the 2^n sign flips, one flip at a time. The claims
    run dozens of these per table at 8-12 episodes per condition, and they took half of a claims job's time. Under
    the null every non-zero difference's sign flips independently and the ranks stay fixed, so the rank sum's
    null distribution is that of a sum of independent terms (0 or a rank each): counting it by convolution over
    the doubled ranks (integers, as average ranks are multiples of 1/2) gives the same p, exactly. A zero's flip
    changes nothing, so it scales every count alike and leaves the p unchanged. Every other case is scipy's.
    """
    d = np.asarray(d, np.float64)
    nonzero = d[d != 0]
    ranks = sps.rankdata(np.abs(nonzero))
    ties_or_zeros = nonzero.size < d.size or np.unique(ranks).size < ranks.size
    if not (0 < nonzero.size and d.size <= PERMUTATION_MAX_N and ties_or_zeros):
        res = sps.wilcoxon(d, alternative=alternative)
        return float(res.statistic), float(res.pvalue)
    doubled = np.rint(2 * ranks).astype(np.int64)
    counts = np.zeros(doubled.sum() + 1, np.int64)  # counts[t]: sign flips whose doubled positive rank sum is t
    counts[0] = 1
    for r in doubled:
        counts[r:] = counts[r:] + counts[:-r]  # the right side is evaluated first: each flip counted once
    r_plus = float(ranks[nonzero > 0].sum())
    t = int(np.rint(2 * r_plus))
    flips = float(2 ** nonzero.size)
    p_less, p_greater = counts[:t + 1].sum() / flips, counts[t:].sum() / flips
    p = {"less": p_less, "greater": p_greater, "two-sided": min(1.0, 2 * min(p_less, p_greater))}[alternative]
    statistic = min(r_plus, float(ranks.sum()) - r_plus) if alternative == "two-sided" else r_plus
    return statistic, float(p)


def wilcoxon_paired(df: pd.DataFrame, value: str, group: str, control, pair_on: str | list[str]) -> pd.DataFrame:
    """Two-sided Wilcoxon signed-rank test of every group against ``control``, paired by ``pair_on``.

    Rows of ``df`` with equal ``pair_on`` keys (e.g. ``episode``) are matched; a
    key missing from either group is left out, and ``n`` counts the pairs. The
    effect is the median of the paired differences (group minus control).
    """
    keys = [pair_on] if isinstance(pair_on, str) else list(pair_on)
    require(df, [*keys, value, group], "table")
    if df.empty:
        return _single_nan_row("wilcoxon", control, "median paired difference", "empty table")
    if control not in set(df[group]):
        raise ValueError(f"control {control!r} is not a value of column {group!r}")
    if df.duplicated([*keys, group]).any():
        raise ValueError(f"more than one row per ({', '.join(keys)}, {group}): pairs are ambiguous")
    wide = df.pivot(index=keys, columns=group, values=value)
    if len(wide.columns) < 2:
        return _single_nan_row("wilcoxon", control, "median paired difference", "no group besides the control")
    rows = []
    for g in [c for c in wide.columns if c != control]:
        both = wide[[g, control]].astype(np.float64).dropna()
        d = (both[g] - both[control]).to_numpy()
        effect = float(np.median(d)) if d.size else np.nan
        reason = "no complete pairs" if d.size == 0 else ("all paired differences are zero" if np.all(d == 0) else "")
        if reason:
            rows.append(_row("wilcoxon", g, control, d.size, d.size, effect, "median paired difference",
                             reason=reason))
            continue
        statistic, p = signed_rank_test(d, "two-sided")
        rows.append(_row("wilcoxon", g, control, d.size, d.size, effect, "median paired difference", statistic, p))
    return pd.DataFrame(rows, columns=STAT_COLUMNS)


def spearman(df: pd.DataFrame, x: str, y: str, by: str | None = None) -> pd.DataFrame:
    """Spearman rank correlation of ``y`` with ``x`` (scipy.stats.spearmanr), one row per value of ``by``.

    The effect and the statistic are rho; ``group`` is the ``by`` value (or
    ``"all"``) and ``control`` names the x column.
    """
    require(df, [x, y] + ([by] if by else []), "table")
    rows = []
    for g, sub in (list(df.groupby(by, sort=True)) if by else []) or [("all", df)]:
        xy = sub[[x, y]].astype(np.float64).dropna().to_numpy()
        reason = "fewer than 3 finite pairs" if len(xy) < 3 else ""
        if not reason and (np.ptp(xy[:, 0]) == 0 or np.ptp(xy[:, 1]) == 0):
            reason = f"{x if np.ptp(xy[:, 0]) == 0 else y} is constant"
        if reason:
            rows.append(_row("spearman", g, x, len(xy), len(xy), np.nan, "rho", reason=reason))
            continue
        res = sps.spearmanr(xy[:, 0], xy[:, 1])
        rows.append(_row("spearman", g, x, len(xy), len(xy), res.statistic, "rho", res.statistic, res.pvalue))
    return pd.DataFrame(rows, columns=STAT_COLUMNS)


def fisher_row(group, control, k: int, n: int, k_control: int, n_control: int) -> pd.DataFrame:
    """Two-sided Fisher exact test of ``k`` successes in ``n`` trials against ``k_control`` in ``n_control``.

    One row of STAT_COLUMNS: the effect is the rate difference (group minus
    control), the statistic the sample odds ratio. NaN with a reason when a
    group has no trial.
    """
    if n <= 0 or n_control <= 0:
        return pd.DataFrame([_row("fisher", group, control, max(n, 0), max(n_control, 0), np.nan, "rate difference",
                                  reason=f"no trials in {group if n <= 0 else control!r}")], columns=STAT_COLUMNS)
    res = sps.fisher_exact([[k, n - k], [k_control, n_control - k_control]])
    return pd.DataFrame([_row("fisher", group, control, n, n_control, k / n - k_control / n_control,
                              "rate difference", res.statistic, res.pvalue)], columns=STAT_COLUMNS)


def fisher_rates(k1: int, n1: int, k2: int, n2: int) -> tuple[float, float]:
    """Rate difference k1/n1 - k2/n2 and the two-sided p of Fisher's exact test; ValueError for an empty group."""
    if n1 <= 0 or n2 <= 0:
        raise ValueError(f"an empty group ({n1} and {n2} trials)")
    row = fisher_row("group", "control", k1, n1, k2, n2).iloc[0]
    return float(row["effect"]), float(row["p"])


def cluster_sum_t_test(values, clusters) -> dict:
    """Test that the mean over clusters of the per-cluster sum of ``values`` is 0: a t-test on the cluster sums.

    Why: observations of one cluster (e.g. the IDIs of one episode, whose agents share an arena and a policy draw)
    are not independent, so a test that counts each observation as a unit (pseudo-replication) understates the
    variance, and one cluster with many observations can make any effect look significant. Summing within each
    cluster and testing the G sums across clusters treats the cluster as the unit. The variance of the mean sum,
    s^2 / G with s^2 the sample variance of the sums, is the cluster-robust (sandwich) variance of Liang & Zeger
    (1986, Biometrika 73:13) for an intercept at the cluster level, with the small-sample factor G / (G - 1)
    (Cameron & Miller 2015, J Hum Resour 50:317, section VI); it allows any correlation within a cluster. With
    few clusters the statistic is referred to t with G - 1 degrees of freedom, not to the normal: the variance is
    estimated from G numbers only (Donald & Lang 2007, Rev Econ Stat 89:221; Bester, Conley & Hansen 2011,
    J Econom 165:137); at G = 12 the normal's 1.96 would reject a true null 7.6% of the time instead of 5%
    (t_11's 0.975 quantile is 2.20). Each cluster weighs the same, whatever its size: the null is that a typical
    cluster's sum is 0.

    Returns ``mean_cluster_sum``, its ``se``, ``t``, ``df`` = G - 1, the two-sided ``p``, ``n_clusters`` (G),
    ``n`` (finite values) and ``reason``, empty unless the numbers are NaN (fewer than 2 clusters, sums that do
    not vary).

    >>> round(cluster_sum_t_test([1.0, 2.0, -1.0, 3.0, 0.5, 0.5], [0, 0, 1, 1, 2, 2])["t"], 3)  # sums 3, 2, 1
    3.464
    """
    v = np.asarray(values, dtype=np.float64)
    labels = pd.Series(np.asarray(clusters))
    ok = np.isfinite(v) & labels.notna().to_numpy()
    sums = pd.Series(v[ok]).groupby(labels[ok].to_numpy(), sort=True).sum().to_numpy()
    g = sums.size
    out = {"mean_cluster_sum": np.nan, "se": np.nan, "t": np.nan, "df": np.nan, "p": np.nan, "n_clusters": g,
           "n": int(ok.sum()), "reason": ""}
    if g < 2:
        return {**out, "reason": f"fewer than 2 clusters ({g})"}
    mean, se = float(sums.mean()), float(sums.std(ddof=1) / np.sqrt(g))
    out.update(mean_cluster_sum=mean, se=se, df=float(g - 1))
    if not se > 1e-12 * np.abs(sums).max():  # equal sums differ by rounding only: no variance to test against
        return {**out, "reason": "the cluster sums do not vary"}
    t = mean / se
    return {**out, "t": t, "p": float(2 * sps.t.sf(abs(t), g - 1))}
