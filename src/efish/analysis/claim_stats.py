"""The statistics the claims' revised rules need (docs/claims/index.md) that no analysis table holds.

- :func:`paired_vs_control`: every condition against a control, paired over
  the episodes they share (Wilcoxon signed-rank), Holm-corrected over the
  conditions: the paired counterpart of Dunnett's many-to-one test. Conditions
  of one assay share their episode seeds (same starts, same food), so episode
  ``e`` of one condition is the natural pair of episode ``e`` of the control;
  pairing removes the between-episode variance that an unpaired test keeps.
- :func:`equivalence_margin`, :func:`tost_paired`, :func:`tost_unpaired`:
  two one-sided tests (TOST) for a statement the paper reports as "no
  difference". A large n makes equivalence easier to show, where "p >= 0.05"
  made it harder. The tests are the rank tests of the difference (Wilcoxon
  signed-rank on shifted differences; Mann-Whitney on a shifted sample), so an
  "n.s." part and its neighbours use the same kind of test.
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
from collections.abc import Sequence

import numpy as np
import pandas as pd
from scipy import stats as sps

from .inequality import theil_t
from .stats import STAT_COLUMNS, signed_rank_test, wilcoxon_paired


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


# ------------------------------------------------------------------ equivalence
def equivalence_margin(control: np.ndarray, pooled_sd: float, fraction: float, sd_fraction: float) -> tuple[float, str]:
    """The equivalence margin of an "n.s." part and how it was chosen.

    ``fraction`` of the control's median, unless that median is near 0 (within
    one pooled SD of it, where a relative margin shrinks to nothing): then
    ``sd_fraction`` pooled SDs. ValueError when neither gives a positive margin.
    """
    c = np.asarray(control, np.float64)
    c = c[np.isfinite(c)]
    if c.size == 0:
        raise ValueError("no finite control value for an equivalence margin")
    med = float(np.median(c))
    if abs(med) > pooled_sd and fraction * abs(med) > 0:
        return fraction * abs(med), f"{fraction:g} x control median {med:.3g}"
    if sd_fraction * pooled_sd > 0:
        return sd_fraction * pooled_sd, f"{sd_fraction:g} pooled SD ({pooled_sd:.3g}; control median {med:.3g} near 0)"
    raise ValueError("no variation and a zero control median: no equivalence margin")


def pooled_sd(a: np.ndarray, b: np.ndarray) -> float:
    """Pooled standard deviation of two samples (NaN-free), 0 when neither varies."""
    a, b = (np.asarray(x, np.float64) for x in (a, b))
    dof = max(len(a) + len(b) - 2, 1)
    return float(np.sqrt((np.sum((a - a.mean()) ** 2) + np.sum((b - b.mean()) ** 2)) / dof))


def tost_paired(diff: np.ndarray, margin: float) -> float:
    """TOST p that the median paired difference lies within (-margin, margin): Wilcoxon signed-rank tests of
    diff + margin > 0 and diff - margin < 0; the larger of the two one-sided p's."""
    d = np.asarray(diff, np.float64)
    d = d[np.isfinite(d)]
    if d.size < 2:
        raise ValueError(f"fewer than 2 paired differences for an equivalence test ({d.size})")
    lower = signed_rank_test(d + margin, "greater")[1] if np.any(d + margin) else 1.0
    upper = signed_rank_test(d - margin, "less")[1] if np.any(d - margin) else 1.0
    return float(max(lower, upper))


def tost_unpaired(x: np.ndarray, control: np.ndarray, margin: float) -> float:
    """TOST p that ``x`` and ``control`` differ by less than ``margin`` in location: Mann-Whitney tests of
    x + margin > control and x - margin < control; the larger one-sided p."""
    x, c = (np.asarray(v, np.float64) for v in (x, control))
    x, c = x[np.isfinite(x)], c[np.isfinite(c)]
    if x.size < 2 or c.size < 2:
        raise ValueError(f"fewer than 2 values per group for an equivalence test ({x.size}, {c.size})")
    lower = sps.mannwhitneyu(x + margin, c, alternative="greater").pvalue
    upper = sps.mannwhitneyu(x - margin, c, alternative="less").pvalue
    return float(max(lower, upper))


def welch_tost(x: np.ndarray, control: np.ndarray, margin: float) -> tuple[float, float, float]:
    """Difference of means (x minus control), its two-sided Welch p, and the Welch TOST p within ``margin``.

    For a quantity defined against an expectation (the excess Theil T is the
    observed minus the null's mean), the means are what the null equalises, so
    the t-tests are the matching tests; a rank test would also pick up the
    null's skew, which differs with the total.
    """
    x, c = (np.asarray(v, np.float64) for v in (x, control))
    x, c = x[np.isfinite(x)], c[np.isfinite(c)]
    if x.size < 2 or c.size < 2:
        raise ValueError(f"fewer than 2 values per group for a t-test ({x.size}, {c.size})")
    p = sps.ttest_ind(x, c, equal_var=False).pvalue
    lower = sps.ttest_ind(x + margin, c, equal_var=False, alternative="greater").pvalue
    upper = sps.ttest_ind(x - margin, c, equal_var=False, alternative="less").pvalue
    return float(x.mean() - c.mean()), float(p), float(max(lower, upper))


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
def eaten_fraction(summary: pd.DataFrame, food: pd.DataFrame, eaten: str = "food_total") -> pd.Series:
    """Per (condition, episode): pellets eaten / pellets that existed (the food table's records), NaN for none."""
    offered = food.groupby(["condition", "episode"]).size().rename("offered")
    joined = summary.set_index(["condition", "episode"])[[eaten]].join(offered)
    return (joined[eaten] / joined["offered"].where(joined["offered"] > 0)).rename("eaten_fraction")


def at_ceiling(summary: pd.DataFrame, food: pd.DataFrame, condition: str, share: float) -> tuple[bool, str]:
    """Whether ``condition`` ate every pellet there was in at least ``share`` of its episodes (a ceiling), and a
    sentence saying how often it did."""
    frac = eaten_fraction(summary, food)
    mine = frac.xs(condition, level="condition").dropna() if condition in frac.index.get_level_values(0) else frac[:0]
    if mine.empty:
        return False, f"no pellet record for {condition}"
    full = float(np.mean(mine >= 1.0))
    return full >= share, (f"{condition} ate every pellet in {full:.0%} of its {len(mine)} episodes "
                           f"(mean {mine.mean():.0%} eaten)")


# ------------------------------------------------------------------ interaction
def interaction_slope(x: np.ndarray, y: np.ndarray, on: np.ndarray) -> tuple[float, float, int]:
    """Slope of y on x where ``on`` minus the slope where not, from one OLS fit y ~ 1 + x + on + x:on, with the
    two-sided t-test p of the interaction coefficient and n; ValueError where the design cannot give it."""
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
    se = np.sqrt(sigma2 * np.linalg.inv(design.T @ design)[3, 3])
    if se == 0:
        return float(coef[3]), 0.0 if coef[3] != 0 else 1.0, len(y)
    p = 2 * sps.t.sf(abs(coef[3] / se), dof)
    return float(coef[3]), float(p), len(y)
