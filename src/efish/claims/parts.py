"""The parts claims share: a test on an analysis table's rows turned into an :class:`~efish.claims.verdicts.Outcome`
with an interval over episodes.

Each builder takes the claim's :class:`~efish.claims.context.Context` (its
tables, config and seeded generator), runs one test (Mann-Whitney, Spearman, a
one-sample or paired Wilcoxon; paired tests against a control
with Holm's correction; a "no difference" statement is the same test, decided against delta) and
returns its Outcome; :func:`ceiling` says when a food test cannot be decided.
A statistic an analysis table already holds is read (:func:`stat_row`,
:func:`from_row`), not recomputed.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Callable, Iterable

import numpy as np
import pandas as pd

from ..analysis.stats import mann_whitney, signed_rank_test, spearman
from .context import Context
from .intervals import (
    rank_sum_interval,
    signed_rank_interval,
    smallest_p_rank_correlation,
    smallest_p_rank_sum,
    smallest_p_signed_rank,
    spearman_fisher_z,
)
from .statistics import at_ceiling, paired_vs_control, slope
from .verdicts import Outcome


def present(frame: pd.DataFrame, column: str, values: Iterable, what: str) -> None:
    """ValueError naming the values of ``column`` that ``frame`` lacks (a condition with no data)."""
    if missing := [v for v in values if v not in set(frame[column].dropna())]:
        raise ValueError(f"no {what} for {column} {missing}")


EPISODE_KEYS = ["condition", "episode"]


def per_episode(frame: pd.DataFrame, value: str, stat: Callable[[pd.DataFrame], float] | None = None) -> pd.DataFrame:
    """One row per episode (condition, episode) of ``frame``'s units (agents, events, bins): the mean of ``value``,
    or ``stat`` of the episode's rows (a slope, a correlation) named ``value``; episodes where it is undefined
    (NaN) are dropped. Rule 1: a test then runs across episodes, never across the units inside them."""
    keys = [k for k in EPISODE_KEYS if k in frame.columns]
    if stat is None:
        out = frame.groupby(keys, as_index=False)[value].mean()
    else:
        out = pd.DataFrame([{**dict(zip(keys, k if isinstance(k, tuple) else (k,), strict=True)), value: stat(g)}
                            for k, g in frame.groupby(keys, sort=True)], columns=[*keys, value])
    return out.dropna(subset=[value])


def slope_of(x: str, y: str) -> Callable[[pd.DataFrame], float]:
    """The OLS slope of ``y`` on ``x`` within a frame (NaN where undefined), e.g. one episode's agents."""
    return lambda d: slope(d[x], d[y])


def stat_row(rows: pd.DataFrame, **match) -> pd.Series:
    """The one statistic row matching ``match`` (e.g. measure='bite'); ValueError naming what is missing."""
    sel = rows
    for k, v in match.items():
        sel = sel[sel[k] == v] if k in sel.columns else sel.iloc[0:0]
    if sel.empty:
        raise ValueError(f"no statistic row with {match}")
    return sel.iloc[0]


def from_row(row: pd.Series, sign: int | None, ci: tuple[float, float], note: str = "") -> Outcome:
    """An :class:`Outcome` from a :mod:`efish.analysis.stats` row (effect, p, n, reason)."""
    reason = row.get("reason")
    reason = reason if isinstance(reason, str) else ""
    return Outcome(float(row["effect"]), float(row["p"]), int(row["n"]), sign, ci, reason or note)


def signed_rank_outcome(ctx: Context, d, sign: int | None, p_adjusted: float | None = None, family: int = 1,
                        units_: str = "episodes", reference: float = np.nan) -> Outcome:
    """The signed-rank test of the differences ``d`` against 0 as an Outcome: the effect is their Hodges-Lehmann
    estimate and the interval the shifts the test does not reject at level 1 - 2 alpha / ``family``
    (:func:`efish.claims.intervals.signed_rank_interval`; :meth:`Context.level`), the one a decision against delta
    reads.

    ``p_adjusted``: the comparison's Holm-adjusted p within a ``family`` of that many comparisons; the smallest
    reachable p is then the family's. All-zero differences test nothing: effect 0, interval [0, 0] and p 1.
    ``reference``: the median of the term the differences subtract (a relative delta scales it).
    """
    d = np.asarray(d, np.float64)
    d = d[np.isfinite(d)]
    if d.size == 0:
        raise ValueError(f"no {units_} with a finite difference")
    if not np.any(d):  # no difference at all is data, not a small n: the floor is what n differences could reach
        return Outcome(0.0, 1.0, d.size, sign, (0.0, 0.0), f"no difference in any of the {d.size} {units_}",
                       ci_method="no difference to invert",
                       p_floor=min(1.0, family * smallest_p_signed_rank(d.size)), family=family, reference=reference)
    floor = min(1.0, family * smallest_p_signed_rank(int(np.count_nonzero(d))))
    p_raw = signed_rank_test(d, "two-sided")[1]
    p = p_raw if p_adjusted is None else float(p_adjusted)
    level = ctx.level(family)
    interval = signed_rank_interval(d, 1 - level)
    method = f"inverts the signed-rank test, level {level:.3g}" + (f" (Bonferroni over {family})" if family > 1 else "")
    return Outcome(interval.estimate, p, d.size, sign, (interval.low, interval.high), ci_method=method,
                   p_floor=floor, family=family, reference=reference)


def mann_whitney_part(ctx: Context, frame: pd.DataFrame, value: str, group: str, a, b, sign: int | None) -> Outcome:
    """Mann-Whitney of ``value``, group ``a`` vs ``b`` (the reference, whose median the outcome records): effect the
    Hodges-Lehmann shift a - b, interval the shifts the test does not reject at the parts' level
    (:func:`efish.claims.intervals.rank_sum_interval`)."""
    present(frame, group, [a, b], f"finite {value}")
    sub = frame[frame[group].isin([a, b])]
    row = mann_whitney(sub, value, group, b).set_index("group").loc[a]
    x, y = (sub.loc[sub[group] == g, value].to_numpy(np.float64) for g in (a, b))
    x, y = x[np.isfinite(x)], y[np.isfinite(y)]
    interval = rank_sum_interval(x, y, 1 - ctx.level())
    out = from_row(row, sign, (interval.low, interval.high))
    return dataclasses.replace(out, effect=interval.estimate, ci_method=f"inverts the Mann-Whitney test, level "
                               f"{ctx.level():.3g}", p_floor=smallest_p_rank_sum(x.size, y.size),
                               reference=float(np.median(y)) if y.size else np.nan)


def spearman_part(ctx: Context, frame: pd.DataFrame, x: str, y: str, sign: int | None) -> Outcome:
    """Spearman rho of ``y`` with ``x`` over the rows of ``frame`` (one per episode), tested by Fisher's z with the
    interval that inverts it at the parts' level (:func:`efish.claims.intervals.spearman_fisher_z`)."""
    row = spearman(frame, x, y).iloc[0]
    rho, n = float(row["effect"]), int(row["n"])
    if not np.isfinite(rho):
        return from_row(row, sign, (np.nan, np.nan))
    p, interval = spearman_fisher_z(rho, n, 1 - ctx.level())
    return Outcome(rho, p, n, sign, (interval.low, interval.high),
                   ci_method=f"inverts the Fisher-z test, level {ctx.level():.3g}",
                   p_floor=smallest_p_rank_correlation(n))


def one_sample_part(ctx: Context, frame: pd.DataFrame, value: str, reference: float, sign: int,
                    units_: str = "episodes") -> Outcome:
    """Signed-rank test of ``value`` against ``reference``, one value per row of ``frame`` (effect: the
    Hodges-Lehmann estimate of value - reference; :func:`signed_rank_outcome`)."""
    return signed_rank_outcome(ctx, frame[value].to_numpy(np.float64) - reference, sign, units_=units_)


def paired_difference(ctx: Context, long: pd.DataFrame, better: str, worse: str, value: str = "skill",
                      key: str = "target", unit: str | Iterable[str] = ("condition", "episode"),
                      sign: int = +1) -> Outcome:
    """Signed-rank test over ``unit`` (the columns that name an episode) of ``value`` where ``key`` is ``better``
    minus where it is ``worse`` (e.g. two decoding targets' held-out skill), units with both only
    (:func:`signed_rank_outcome`)."""
    wide = long.pivot(index=unit if isinstance(unit, str) else list(unit), columns=key, values=value)
    present(pd.DataFrame({key: list(wide.columns)}), key, [better, worse], f"{value}")
    diff = (wide[better] - wide[worse]).dropna()
    return signed_rank_outcome(ctx, diff.to_numpy(np.float64), sign)


def decoded(ctx: Context, path: str, targets: Iterable[str], **match) -> pd.DataFrame:
    """The rows of a per-episode decoding table (dynamics ``decoding_episodes``, ``food_decoding_episodes``) of
    ``targets`` matching ``match`` (e.g. condition=...) with a finite skill; a ValueError with the analysis's reason
    when a target has none (a column the rollout lacks, too few episodes)."""
    rows = ctx.table(path)
    rows = rows[rows["target"].isin(list(targets))]
    for column, value in match.items():
        rows = rows[rows[column] == value]
    for target in targets:
        mine = rows[rows["target"] == target]
        if not np.isfinite(mine["skill"].to_numpy(np.float64)).any():
            reasons = sorted({r for r in mine["reason"] if isinstance(r, str) and r})
            why = "; ".join(reasons) or "no row" + "".join(f", {k} {v}" for k, v in match.items())
            raise ValueError(f"no decoding skill of {target} ({why}) in {path}")
    return rows[np.isfinite(rows["skill"].to_numpy(np.float64))]


# ------------------------------------------------- paired parts (paired tests, ceilings)
def paired_part(ctx: Context, summary: pd.DataFrame, measure: str, condition: str, control: str,
                sign: int, family: Iterable[str]) -> Outcome:
    """``condition`` vs ``control`` paired over their shared episodes (:func:`signed_rank_outcome`), the p
    Holm-adjusted and the interval Bonferroni-widened over ``family``: the conditions whose comparison with the
    same control on the same measure a part tests; the control's median is the reference. Not decidable at a
    floor (``measure`` 0 in every episode of both)."""
    present(summary, "condition", [condition, control], f"episodes with {measure}")
    compared = [*dict.fromkeys([*family, condition])]
    rows = paired_vs_control(summary[summary["condition"].isin([*compared, control])], measure, control)
    row = rows.set_index("group").loc[condition]
    wide = summary[summary["condition"].isin([condition, control])].pivot(index="episode", columns="condition",
                                                                          values=measure).astype(np.float64)
    both = wide[[condition, control]].dropna()
    note = f"paired over {len(both)} shared episodes, Holm over {len(compared)} vs {control}"
    if len(both) and not both.to_numpy().any():
        return Outcome(np.nan, np.nan, len(both), sign, verdict="not decidable",
                       reason=f"at a floor: {measure} is 0 in every episode of {condition} and {control} ({note})")
    d = (both[condition] - both[control]).to_numpy()
    size = int(np.isfinite(rows["p_raw"]).sum())
    out = signed_rank_outcome(ctx, d, sign, p_adjusted=row["p"] if np.any(d) else None, family=max(size, 1),
                              reference=float(both[control].median()) if len(both) else np.nan)
    return dataclasses.replace(out, reason="; ".join(r for r in (out.reason, note) if r))


def ceiling(ctx: Context, summary: pd.DataFrame, conditions: Iterable[str]) -> Outcome | None:
    """A "not decidable" outcome when one of ``conditions`` ate every pellet in most episodes (a ceiling), else None."""
    share = ctx.cfg.analysis.claims_ceiling_share
    for condition in conditions:
        full, how = at_ceiling(summary, condition, share)
        if full:
            return Outcome(np.nan, np.nan, int((summary["condition"] == condition).sum()), None,
                           verdict="not decidable", reason=f"at a ceiling: {how}, so no food difference can appear")
    return None
