"""The statistics of the claims' rules (docs/claims/index.md) that no analysis table holds.

- :func:`bootstrap_ci`: a percentile interval over resampled units (episodes),
  each unit's rows kept together, optionally within strata (conditions).
- :func:`jackknife_ci`: a jackknife t interval over units, for a statistic a
  bootstrap biases (Kendall's W: an episode drawn twice agrees with itself).
- :func:`ols`, :func:`slope`: an OLS slope with its p; and the statistics a
  bootstrap recomputes per resample (:func:`mean_diff`, :func:`rho_of`).
- :func:`paired_vs_control`: every condition against a control, paired over
  the episodes they share (Wilcoxon signed-rank), Holm-corrected over the
  conditions: the paired counterpart of Dunnett's many-to-one test. Conditions
  of one assay share their episode seeds (same starts, same food), so episode
  ``e`` of one condition is the natural pair of episode ``e`` of the control;
  pairing removes the between-episode variance that an unpaired test keeps.
- :func:`welch_difference`: a difference of means with its Welch test and
  interval (C13's excess Theil T, whose null equalises means).
- :func:`excess_theil`: Theil T above what equal shares give at the same
  totals. Theil T of a multinomial draw of F pellets among n agents with equal
  shares is about (n - 1) / (2F) for large F: a condition that eats less looks
  more unequal by chance alone.
- :func:`at_ceiling`: whether a condition eats every pellet there is, so no
  food difference can appear.
- :func:`interaction_slope`: the difference of two OLS slopes (the N x K
  interaction of C17) with its t-test.
"""

from __future__ import annotations

import functools
from collections.abc import Callable, Sequence

import numpy as np
import pandas as pd
from scipy import stats as sps

from ..analysis.inequality import theil_t
from ..analysis.stats import STAT_COLUMNS, wilcoxon_paired
from .verdicts import NAN_CI


# ------------------------------------------------------------------ bootstrap
def bootstrap_ci(data: pd.DataFrame, stat: Callable[[pd.DataFrame], float], units: list[str],
                 resamples: int, rng: np.random.Generator, strata: str | None = None,
                 level: float = 0.95) -> tuple[float, float]:
    """Percentile interval of ``stat`` over resamples of ``data``'s units (e.g. episodes), drawn with replacement.

    A unit is a value of the ``units`` columns; every row of a drawn unit comes
    along (an episode's agents stay together). With ``strata`` (e.g. condition)
    each stratum's units are drawn separately, as many as it has. The resample
    gets a ``_draw`` column numbering the drawn units, so that a statistic that
    pairs rows can tell a unit drawn twice apart. NaN when fewer than half of the
    resamples give a finite value (the statistic is undefined too often).
    """
    if data.empty or resamples < 1:
        return NAN_CI
    keys = ([strata] if strata else []) + list(units)
    index = data.groupby(keys, sort=True, dropna=False).indices
    groups = list(index.values())
    stratum, _ = pd.factorize(pd.Series([k[0] for k in index] if strata else [0] * len(groups), dtype=object))
    pools = [np.flatnonzero(stratum == s) for s in range(stratum.max() + 1)]
    lengths = np.array([len(g) for g in groups])
    values = np.empty(resamples)
    for b in range(resamples):
        chosen = np.concatenate([rng.choice(pool, size=len(pool), replace=True) for pool in pools])
        rows = np.concatenate([groups[u] for u in chosen])
        sample = data.iloc[rows].assign(_draw=np.repeat(np.arange(len(chosen)), lengths[chosen]))
        values[b] = stat(sample)
    finite = values[np.isfinite(values)]
    if finite.size < resamples / 2:
        return NAN_CI
    tail = 100 * (1 - level) / 2
    lo, hi = np.percentile(finite, [tail, 100 - tail])
    return float(lo), float(hi)


def jackknife_ci(units: np.ndarray, stat: Callable[[np.ndarray], float],
                 alpha: float = 0.05) -> tuple[float, float]:
    """Tukey's jackknife t interval of ``stat`` over the rows of ``units`` (one row per unit, e.g. an episode's
    block of a Friedman test): ``stat(units)`` +- t(1 - alpha / 2, n - 1) x the jackknife standard error from the n
    leave-one-unit-out values. NaN when a leave-one-out value is not finite (too few units).

    Centred on the estimate, so it always contains it; where the statistic is a U-statistic (the mean over pairs
    of units of a kernel, such as the mean Spearman correlation between episodes behind Kendall's W) the
    jackknife's variance is consistent (Arvesen 1969) and its bias estimate exactly 0. A bootstrap of such a
    statistic is biased: a unit drawn twice pairs with itself.

    >>> [round(v, 3) for v in jackknife_ci(np.arange(1.0, 6.0)[:, None], lambda u: float(u.mean()))]
    [1.037, 4.963]
    """
    u = np.asarray(units)
    n = len(u)
    if n < 3:
        return NAN_CI
    estimate = stat(u)
    left_out = np.array([stat(np.delete(u, i, axis=0)) for i in range(n)], np.float64)
    if not (np.isfinite(estimate) and np.isfinite(left_out).all()):
        return NAN_CI
    se = float(np.sqrt((n - 1) / n * np.sum((left_out - left_out.mean()) ** 2)))
    half = float(sps.t.ppf(1 - alpha / 2, n - 1)) * se
    return float(estimate - half), float(estimate + half)


def ols(x, y) -> tuple[float, float, int]:
    """Slope of y on x by least squares, its two-sided p (scipy.stats.linregress) and n; ValueError if undefined."""
    xy = np.column_stack([np.asarray(x, np.float64), np.asarray(y, np.float64)])
    xy = xy[np.all(np.isfinite(xy), axis=1)]
    if len(xy) < 3:
        raise ValueError(f"fewer than 3 finite points for a slope ({len(xy)})")
    if np.ptp(xy[:, 0]) == 0:
        raise ValueError("the regressor is constant")
    if np.ptp(xy[:, 1]) == 0:
        raise ValueError("the response is constant")
    fit = sps.linregress(xy[:, 0], xy[:, 1])
    return float(fit.slope), float(fit.pvalue), len(xy)


def slope(x, y) -> float:
    """The OLS slope alone (NaN where undefined): the bootstrap's statistic for :func:`ols`."""
    try:
        return ols(x, y)[0]
    except ValueError:
        return np.nan


# ------------------------------------------------------------------ statistics a bootstrap recomputes
def mean_diff(value: str, group: str, a, b) -> Callable[[pd.DataFrame], float]:
    def stat(d: pd.DataFrame) -> float:
        x, y = d.loc[d[group] == a, value].dropna(), d.loc[d[group] == b, value].dropna()
        return float(x.mean() - y.mean()) if len(x) and len(y) else np.nan
    return stat


def rho_of(x: str, y: str) -> Callable[[pd.DataFrame], float]:
    def stat(d: pd.DataFrame) -> float:
        xy = d[[x, y]].astype(np.float64).dropna()
        if len(xy) < 3 or xy[x].nunique() < 2 or xy[y].nunique() < 2:
            return np.nan
        return float(sps.spearmanr(xy[x], xy[y]).statistic)
    return stat


# ------------------------------------------------------------------ paired tests
def holm(p: Sequence[float]) -> np.ndarray:
    """Holm's step-down adjusted p-values (NaN entries stay NaN and do not count in the family).

    >>> holm([0.01, 0.04, 0.03]).round(3).tolist()
    [0.03, 0.06, 0.06]
    """
    p = np.asarray(p, np.float64)
    out = np.full(p.shape, np.nan)
    ok = np.flatnonzero(np.isfinite(p))
    order = ok[np.argsort(p[ok], kind="stable")]
    m, running = len(order), 0.0
    for rank, i in enumerate(order):
        running = max(running, min(1.0, (m - rank) * p[i]))
        out[i] = running
    return out


def paired_vs_control(summary: pd.DataFrame, measure: str, control: str, condition: str = "condition",
                      episode: str = "episode") -> pd.DataFrame:
    """Paired Wilcoxon of ``measure`` for every condition against ``control`` over shared episodes, Holm-adjusted.

    ``summary``: one row per (condition, episode). Rows: :data:`STAT_COLUMNS`
    plus ``p_raw`` (unadjusted) and ``measure``; ``p`` is Holm-adjusted over
    every condition compared with the control in this call (the whole family,
    as Dunnett's test would be).
    """
    rows = wilcoxon_paired(summary[[condition, episode, measure]], measure, condition, control, episode)
    rows = rows.assign(p_raw=rows["p"], p=holm(rows["p"]), measure=measure)
    return rows[[*STAT_COLUMNS, "p_raw", "measure"]]


def welch_difference(x: np.ndarray, control: np.ndarray, level: float) -> tuple[float, float, tuple[float, float]]:
    """Difference of means (x minus control), its two-sided Welch p, and the Welch interval at ``level`` (the one
    that inverts the test at 1 - ``level``).

    For a quantity defined against an expectation (the excess Theil T is the
    observed minus the null's mean), the means are what the null equalises, so
    the t-test is the matching test; a rank test would also pick up the null's
    skew, which differs with the total.
    """
    x, c = (np.asarray(v, np.float64) for v in (x, control))
    x, c = x[np.isfinite(x)], c[np.isfinite(c)]
    if x.size < 2 or c.size < 2:
        raise ValueError(f"fewer than 2 values per group for a t-test ({x.size}, {c.size})")
    test = sps.ttest_ind(x, c, equal_var=False)
    ci = test.confidence_interval(level)
    return float(x.mean() - c.mean()), float(test.pvalue), (float(ci.low), float(ci.high))


# ------------------------------------------------------------------ inequality
@functools.lru_cache(maxsize=4096)
def null_theil(total: int, agents: int, draws: int = 2000, seed: int = 0) -> float:
    """Mean Theil T of ``total`` pellets shared among ``agents`` by a multinomial with equal shares (Monte Carlo,
    seeded, cached per (total, agents)); NaN for no pellet."""
    if total <= 0 or agents < 1:
        return np.nan
    counts = np.random.default_rng([seed, total, agents]).multinomial(total, np.full(agents, 1 / agents), size=draws)
    r = counts / (total / agents)  # each draw's shares over their mean (the total is the same in every draw)
    with np.errstate(divide="ignore", invalid="ignore"):
        return float(np.where(r > 0, r * np.log(r), 0.0).mean())  # theil_t of each draw, averaged


def excess_theil(foods: Sequence[float]) -> float:
    """Theil T of one episode's per-agent food minus its equal-share multinomial null at the same total;
    NaN when nothing was eaten."""
    f = np.asarray(foods, np.float64)
    total = int(round(f.sum()))
    if total <= 0:
        return np.nan
    return float(theil_t(f) - null_theil(total, len(f)))


def excess_theil_per_episode(per_agent: pd.DataFrame, value: str = "food_eaten",
                             keys: Sequence[str] = ("condition", "episode")) -> pd.DataFrame:
    """``excess_theil`` of every episode of an agent-episode table: keys, ``total``, ``excess_theil``."""
    rows = [{**dict(zip(keys, k if isinstance(k, tuple) else (k,), strict=True)), "total": float(g[value].sum()),
             "excess_theil": excess_theil(g[value].to_numpy())}
            for k, g in per_agent.groupby(list(keys), sort=True)]
    return pd.DataFrame(rows, columns=[*keys, "total", "excess_theil"])


# ------------------------------------------------------------------ ceilings
def eaten_fraction(summary: pd.DataFrame, eaten: str = "food_total") -> pd.Series:
    """Per (condition, episode) of the behaviour analysis's episode summary: pellets eaten / pellets that existed
    (its ``food_offered``), NaN for none."""
    if "food_offered" not in summary.columns:
        raise ValueError("the episode summary has no food_offered column: rerun the behaviour analysis")
    joined = summary.set_index(["condition", "episode"])
    return (joined[eaten] / joined["food_offered"].where(joined["food_offered"] > 0)).rename("eaten_fraction")


def at_ceiling(summary: pd.DataFrame, condition: str, share: float) -> tuple[bool, str]:
    """Whether ``condition`` ate every pellet there was in at least ``share`` of its episodes (a ceiling), and a
    sentence saying how often it did."""
    frac = eaten_fraction(summary)
    mine = frac.xs(condition, level="condition").dropna() if condition in frac.index.get_level_values(0) else frac[:0]
    if mine.empty:
        return False, f"no pellet record for {condition}"
    full = float(np.mean(mine >= 1.0))
    return full >= share, (f"{condition} ate every pellet in {full:.0%} of its {len(mine)} episodes "
                           f"(mean {mine.mean():.0%} eaten)")


# ------------------------------------------------------------------ interaction
def interaction_slope(x: np.ndarray, y: np.ndarray, on: np.ndarray,
                      alpha: float = 0.05) -> tuple[float, float, int, tuple[float, float]]:
    """Slope of y on x where ``on`` minus the slope where not, from one OLS fit y ~ 1 + x + on + x:on, with the
    two-sided t-test p of the interaction coefficient, n, and its 1 - ``alpha`` t interval (the one the test
    inverts); ValueError where the design cannot give it."""
    x, y, on = (np.asarray(v, np.float64) for v in (x, y, on))
    keep = np.isfinite(x) & np.isfinite(y) & np.isfinite(on)
    x, y, on = x[keep], y[keep], on[keep]
    for flag in (0.0, 1.0):
        if np.unique(x[on == flag]).size < 2:
            raise ValueError(f"fewer than 2 distinct x values {'with' if flag else 'without'} the factor")
    design = np.column_stack([np.ones_like(x), x, on, x * on])
    coef, *_ = np.linalg.lstsq(design, y, rcond=None)
    dof = len(y) - design.shape[1]
    if dof < 1:
        raise ValueError(f"too few points for an interaction ({len(y)})")
    resid = y - design @ coef
    sigma2 = resid @ resid / dof
    se = float(np.sqrt(sigma2 * np.linalg.inv(design.T @ design)[3, 3]))
    b = float(coef[3])
    if se == 0:
        return b, 0.0 if b != 0 else 1.0, len(y), (b, b)
    half = float(sps.t.ppf(1 - alpha / 2, dof)) * se
    return b, float(2 * sps.t.sf(abs(b / se), dof)), len(y), (b - half, b + half)
