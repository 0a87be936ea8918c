"""The parts claims share: a test on an analysis table's rows turned into an :class:`~efish.claims.verdicts.Outcome`
with an interval over episodes.

Each builder takes the claim's :class:`~efish.claims.context.Context` (its
tables, config and seeded generator), runs one test (Mann-Whitney, Spearman, a
one-sample or paired Wilcoxon, an OLS slope; paired tests against a control
with Holm's correction; equivalence tests for "no difference" statements) and
returns its Outcome; :func:`ceiling` says when a food test cannot be decided.
A statistic an analysis table already holds is read (:func:`stat_row`,
:func:`from_row`), not recomputed.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Iterable

import numpy as np
import pandas as pd

from ..analysis._tables import AGENT_EPISODE
from ..analysis.dynamics import units
from ..analysis.stats import mann_whitney, spearman, wilcoxon_paired
from .context import Context
from .statistics import (
    at_ceiling,
    equivalence_margin,
    median_diff,
    median_minus,
    ols,
    paired_vs_control,
    pooled_sd,
    rho_of,
    slope,
    tost_paired,
    tost_unpaired,
    wilcoxon_vs,
)
from .verdicts import Outcome


def present(frame: pd.DataFrame, column: str, values: Iterable, what: str) -> None:
    """ValueError naming the values of ``column`` that ``frame`` lacks (a condition with no data)."""
    if missing := [v for v in values if v not in set(frame[column].dropna())]:
        raise ValueError(f"no {what} for {column} {missing}")


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


def mann_whitney_part(ctx: Context, frame: pd.DataFrame, value: str, group: str, a, b, sign: int | None) -> Outcome:
    """Mann-Whitney of ``value``, group ``a`` vs ``b`` (effect: median difference a - b), interval over episodes."""
    present(frame, group, [a, b], f"finite {value}")
    sub = frame[frame[group].isin([a, b])]
    row = mann_whitney(sub, value, group, b).set_index("group").loc[a]
    ci = ctx.ci(sub, median_diff(value, group, a, b), strata=group)
    return from_row(row, sign, ci)



def spearman_part(ctx: Context, frame: pd.DataFrame, x: str, y: str, sign: int | None) -> Outcome:
    """Spearman rho of ``y`` with ``x`` over the rows of ``frame``, interval over episodes."""
    return from_row(spearman(frame, x, y).iloc[0], sign, ctx.ci(frame, rho_of(x, y)))


def one_sample_part(ctx: Context, frame: pd.DataFrame, value: str, reference: float, sign: int,
                units_: Iterable[str] = ("episode",)) -> Outcome:
    """Wilcoxon of ``value`` against ``reference`` (effect: median - reference), interval over ``units_``."""
    row = wilcoxon_vs(frame[value], reference)
    return from_row(row, sign, ctx.ci(frame, median_minus(value, reference), units_))


def ols_part(ctx: Context, frame: pd.DataFrame, x: str, y: str, sign: int) -> Outcome:
    """OLS slope of ``y`` on ``x`` with its p, interval over episodes."""
    b, p, n = ols(frame[x], frame[y])
    return Outcome(b, p, n, sign, ctx.ci(frame, lambda d: slope(d[x], d[y])))



def joined(ctx: Context, hidden: str, steps: str, columns: list[str]) -> tuple[pd.DataFrame, list[str]]:
    """Hidden rows joined with ``columns`` of the steps table (keys condition, episode, agent, t), and the units."""
    h, s = ctx.table(hidden), ctx.table(steps)
    keys = [*AGENT_EPISODE, "t"]
    return h.merge(s[keys + columns], on=keys).sort_values(keys, kind="stable"), units(h)


def paired_difference(ctx: Context, long: pd.DataFrame, better: str, worse: str, value: str = "skill",
                      key: str = "target", unit: str = "group", sign: int = +1) -> Outcome:
    """Paired Wilcoxon over ``unit`` (episodes) of ``value`` where ``key`` is ``better`` minus where it is ``worse``
    (e.g. two decoding targets' held-out skill), with an interval over the units."""
    long = long.rename(columns={unit: "episode", key: "target", value: "skill"})
    row = wilcoxon_paired(long, "skill", "target", worse, "episode").set_index("group").loc[better]
    wide = long.pivot(index="episode", columns="target", values="skill")
    diff = (wide[better] - wide[worse]).dropna().rename("diff").reset_index()
    return from_row(row, sign, ctx.ci(diff, median_minus("diff", 0.0), strata=None))


# ------------------------------------------------- paired and equivalence parts (paired tests, equivalence, ceilings)
def margin_for(ctx: Context, control: np.ndarray, other: np.ndarray) -> tuple[float, str]:
    """The equivalence margin of an "n.s." part from the config (:func:`efish.claims.statistics.equivalence_margin`)."""
    a = ctx.cfg.analysis
    c, o = (np.asarray(v, np.float64) for v in (control, other))
    sd = pooled_sd(c[np.isfinite(c)], o[np.isfinite(o)])
    return equivalence_margin(c, sd, a.claims_margin_fraction, a.claims_margin_sd)


def paired_part(ctx: Context, summary: pd.DataFrame, measure: str, condition: str, control: str,
                sign: int, family: Iterable[str] | None = None) -> Outcome:
    """``condition`` vs ``control`` paired over their shared episodes: Wilcoxon signed-rank, Holm-adjusted
    over ``family`` (default: every condition of ``summary``) compared with the same control; effect = median paired
    difference with a bootstrap interval over episodes. For ``sign`` 0 also the paired TOST within the margin."""
    present(summary, "condition", [condition, control], f"episodes with {measure}")
    family = list(summary["condition"].unique()) if family is None else [*family, control]
    rows = paired_vs_control(summary[summary["condition"].isin(family)], measure, control)
    row = rows.set_index("group").loc[condition]
    wide = summary[summary["condition"].isin([condition, control])].pivot(index="episode", columns="condition",
                                                                          values=measure).astype(np.float64)
    both = wide[[condition, control]].dropna()
    diff = (both[condition] - both[control]).rename("diff").reset_index()
    ci = ctx.ci(diff, median_minus("diff", 0.0), strata=None)
    note = f"paired over {len(both)} shared episodes, Holm over {len(rows)} conditions vs {control}"
    out = from_row(row, sign, ci)
    if out.reason.startswith("all paired differences are zero"):  # e.g. no condition ate anything: no evidence
        return dataclasses.replace(out, verdict="not decidable", reason=f"{out.reason} ({note})")
    if sign == 0:
        margin, how = margin_for(ctx, both[control].to_numpy(), both[condition].to_numpy())
        out = dataclasses.replace(out, p_equiv=tost_paired(diff["diff"].to_numpy(), margin), margin=margin)
        note += f"; margin {margin:.3g} = {how}"
    return dataclasses.replace(out, reason="; ".join(r for r in (out.reason, note) if r))


def unpaired_equivalence(ctx: Context, frame: pd.DataFrame, value: str, group: str, a, b) -> Outcome:
    """Mann-Whitney of ``value``, ``a`` vs ``b`` (the control), and the unpaired TOST within the margin."""
    out = mann_whitney_part(ctx, frame, value, group, a, b, 0)
    x, c = (frame.loc[frame[group] == g, value].to_numpy(np.float64) for g in (a, b))
    margin, how = margin_for(ctx, c, x)
    return dataclasses.replace(out, p_equiv=tost_unpaired(x, c, margin), margin=margin,
                               reason="; ".join(r for r in (out.reason, f"margin {margin:.3g} = {how}") if r))


def ceiling(ctx: Context, summary: pd.DataFrame, food: pd.DataFrame, conditions: Iterable[str]) -> Outcome | None:
    """A "not decidable" outcome when one of ``conditions`` ate every pellet in most episodes (a ceiling), else None."""
    share = ctx.cfg.analysis.claims_ceiling_share
    for condition in conditions:
        full, how = at_ceiling(summary, food, condition, share)
        if full:
            return Outcome(np.nan, np.nan, int((summary["condition"] == condition).sum()), None,
                           verdict="not decidable", reason=f"at a ceiling: {how}, so no food difference can appear")
    return None
