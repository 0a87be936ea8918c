"""The parts claims share: a test on an analysis table's rows turned into an :class:`~efish.claims.verdicts.Outcome`
with an interval over episodes.

Each builder takes the claim's :class:`~efish.claims.context.Context` (its
tables, config and seeded generator), runs one test (Mann-Whitney, Spearman, a
one-sample or paired Wilcoxon; paired tests against a control
with Holm's correction; equivalence tests for "no difference" statements) and
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
    holm_alpha,
    rank_sum_interval,
    signed_rank_interval,
    smallest_p_rank_correlation,
    smallest_p_rank_sum,
    smallest_p_signed_rank,
    spearman_fisher_z,
)
from .statistics import (
    at_ceiling,
    equivalence_margin,
    paired_vs_control,
    pooled_sd,
    slope,
    tost_paired,
    tost_unpaired,
)
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
                        units_: str = "episodes") -> Outcome:
    """The signed-rank test of the differences ``d`` against 0 as an Outcome: the effect is their Hodges-Lehmann
    estimate and the interval the shifts the test does not reject (:func:`efish.claims.intervals.signed_rank_interval`).

    ``p_adjusted``: the comparison's Holm-adjusted p within a ``family`` of that many comparisons; the interval is
    then taken at the level Holm tests it at, and the smallest reachable p is the family's. All-zero differences
    test nothing: effect 0 and p 1 (the equivalence test of a "no difference" part still can hold).
    """
    d = np.asarray(d, np.float64)
    d = d[np.isfinite(d)]
    if d.size == 0:
        raise ValueError(f"no {units_} with a finite difference")
    alpha = ctx.cfg.analysis.claims_alpha
    if not np.any(d):  # no difference at all is data, not a small n: the floor is what n differences could reach
        return Outcome(0.0, 1.0, d.size, sign, (0.0, 0.0), f"no difference in any of the {d.size} {units_}",
                       ci_method="no difference to invert",
                       p_floor=min(1.0, family * smallest_p_signed_rank(d.size)), family=family)
    floor = min(1.0, family * smallest_p_signed_rank(int(np.count_nonzero(d))))
    p_raw = signed_rank_test(d, "two-sided")[1]
    p = p_raw if p_adjusted is None else float(p_adjusted)
    level = holm_alpha(alpha, p_raw, p)
    interval = signed_rank_interval(d, level)
    method = f"inverts the signed-rank test at {level:.3g}" + (f" (Holm over {family})" if family > 1 else "")
    return Outcome(interval.estimate, p, d.size, sign, (interval.low, interval.high), ci_method=method,
                   p_floor=floor, family=family)


def mann_whitney_part(ctx: Context, frame: pd.DataFrame, value: str, group: str, a, b, sign: int | None) -> Outcome:
    """Mann-Whitney of ``value``, group ``a`` vs ``b``: effect the Hodges-Lehmann shift a - b, interval the shifts
    the test does not reject (:func:`efish.claims.intervals.rank_sum_interval`)."""
    present(frame, group, [a, b], f"finite {value}")
    sub = frame[frame[group].isin([a, b])]
    row = mann_whitney(sub, value, group, b).set_index("group").loc[a]
    x, y = (sub.loc[sub[group] == g, value].to_numpy(np.float64) for g in (a, b))
    x, y = x[np.isfinite(x)], y[np.isfinite(y)]
    interval = rank_sum_interval(x, y, ctx.cfg.analysis.claims_alpha)
    out = from_row(row, sign, (interval.low, interval.high))
    return dataclasses.replace(out, effect=interval.estimate, ci_method="inverts the Mann-Whitney test",
                               p_floor=smallest_p_rank_sum(x.size, y.size))


def spearman_part(ctx: Context, frame: pd.DataFrame, x: str, y: str, sign: int | None) -> Outcome:
    """Spearman rho of ``y`` with ``x`` over the rows of ``frame`` (one per episode), tested by Fisher's z with the
    interval that inverts it (:func:`efish.claims.intervals.spearman_fisher_z`)."""
    row = spearman(frame, x, y).iloc[0]
    rho, n = float(row["effect"]), int(row["n"])
    if not np.isfinite(rho):
        return from_row(row, sign, (np.nan, np.nan))
    p, interval = spearman_fisher_z(rho, n, ctx.cfg.analysis.claims_alpha)
    return Outcome(rho, p, n, sign, (interval.low, interval.high), ci_method="inverts the Fisher-z test",
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


# ------------------------------------------------- paired and equivalence parts (paired tests, equivalence, ceilings)
def margin_for(ctx: Context, control: np.ndarray, spread: float) -> tuple[float, float, str]:
    """The equivalence margin of an "n.s." part from the config (:func:`efish.claims.statistics.equivalence_margin`),
    with ``spread`` the SD it falls back on near a zero control."""
    a = ctx.cfg.analysis
    return equivalence_margin(np.asarray(control, np.float64), spread, a.claims_margin_fraction, a.claims_margin_sd)


def with_margin(ctx: Context, out: Outcome, margin: tuple[float, float, str], p_equiv: float,
                p_zero: float) -> Outcome:
    """``out`` with its equivalence test: the TOST p within the margin, the margin and its ratio in the row.

    ``p_zero`` is the TOST p the part's own test gives to its data shifted to a zero difference (the same spread
    and n): the smallest TOST p the part can reach, its ``p_floor``. Where it is >= alpha the margin is narrower
    than the test can resolve at this n (for a t-test, margin / SE is below the one-sided critical t), so the part
    could not be shown equivalent even at no difference at all: not decidable, as a test that cannot reach
    significance at its n (:func:`~efish.claims.verdicts.unreachable`; the third audit found 11 of 12 seed-level
    equivalence parts so)."""
    m, ratio, how = margin
    notes = [out.reason, f"margin +-{m:.3g} = {how} ({ratio:.0%} of the control's typical value)"]
    if p_zero >= ctx.cfg.analysis.claims_alpha:
        notes.append(f"the margin cannot be shown at this n: a zero difference with this spread gives a TOST p of "
                     f"{p_zero:.3g}")
    return dataclasses.replace(out, p_equiv=p_equiv, margin=m, margin_ratio=ratio, p_floor=p_zero,
                               reason="; ".join(r for r in notes if r))


def paired_part(ctx: Context, summary: pd.DataFrame, measure: str, condition: str, control: str,
                sign: int, family: Iterable[str]) -> Outcome:
    """``condition`` vs ``control`` paired over their shared episodes (:func:`signed_rank_outcome`), the p
    Holm-adjusted over ``family``: the conditions whose comparison with the same control on the same measure a
    part tests. Not decidable at a floor (``measure`` 0 in every episode of both). For ``sign`` 0 also the paired
    TOST within the margin, whose fallback spread is the SD of the paired differences."""
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
    out = signed_rank_outcome(ctx, d, sign, p_adjusted=row["p"] if np.any(d) else None, family=max(size, 1))
    out = dataclasses.replace(out, reason="; ".join(r for r in (out.reason, note) if r))
    if sign != 0:
        return out
    margin = margin_for(ctx, both[control].to_numpy(), float(np.std(d, ddof=1)) if d.size > 1 else 0.0)
    return with_margin(ctx, out, margin, tost_paired(d, margin[0]), tost_paired(d - out.effect, margin[0]))


def unpaired_equivalence(ctx: Context, frame: pd.DataFrame, value: str, group: str, a, b) -> Outcome:
    """Mann-Whitney of ``value``, ``a`` vs ``b`` (the control), and the unpaired TOST within the margin (fallback
    spread: the pooled SD)."""
    out = mann_whitney_part(ctx, frame, value, group, a, b, 0)
    x, c = (frame.loc[frame[group] == g, value].to_numpy(np.float64) for g in (a, b))
    x, c = x[np.isfinite(x)], c[np.isfinite(c)]
    margin = margin_for(ctx, c, pooled_sd(c, x))
    return with_margin(ctx, out, margin, tost_unpaired(x, c, margin[0]), tost_unpaired(x - out.effect, c, margin[0]))


def ceiling(ctx: Context, summary: pd.DataFrame, conditions: Iterable[str]) -> Outcome | None:
    """A "not decidable" outcome when one of ``conditions`` ate every pellet in most episodes (a ceiling), else None."""
    share = ctx.cfg.analysis.claims_ceiling_share
    for condition in conditions:
        full, how = at_ceiling(summary, condition, share)
        if full:
            return Outcome(np.nan, np.nan, int((summary["condition"] == condition).sum()), None,
                           verdict="not decidable", reason=f"at a ceiling: {how}, so no food difference can appear")
    return None
