"""The claims of Fig 4 (C10-C13): ablations, collective sensing, muting, food layouts.

Conditions of one assay
share their episode seeds, so they are compared paired over episodes with a
Holm correction over the conditions compared with the same control; "no
difference" parts are equivalence tests; food parts are not decidable while
the control eats every pellet; Theil T is compared above its equal-share null
where totals differ (the rules: docs/claims/index.md).

Condition names are those of ``config/assay/<assay>.yaml``.
"""

from __future__ import annotations

import functools
import re

import numpy as np
import pandas as pd

from ..layout import analysis_table, assay_table
from .context import Context, claim
from .parts import ceiling, mann_whitney_part, margin_for, paired_part, present, spearman_part
from .statistics import excess_theil_per_episode, mean_diff, welch_tost
from .verdicts import Outcome, Part

# ablation conditions are named by the receptor classes left on (config/assay/ablation4.yaml)
ALL_ON, M_OFF, A_OFF, K_OFF = "M_A_K", "A_K", "M_K", "M_A"
FOOD = "food_total"


def summary(ctx: Context, assay: str) -> pd.DataFrame:
    """The behaviour analysis's episode summary of ``assay``: one row per (condition, episode)."""
    return ctx.table(analysis_table("behaviour", assay, "episode_summary"))


def _vs_control(ctx: Context, assay: str, condition: str, control: str, measure: str, sign: int,
                family: list[str] | None = None) -> Outcome:
    """A paired part of ``assay``; a food part is not decidable when the control is at a ceiling, a bites part
    when neither condition bit at all (a floor)."""
    s = summary(ctx, assay)
    if family is not None:
        s = s[s["condition"].isin([*family, control])]
    if measure == FOOD:
        if (at := ceiling(ctx, s, ctx.table(assay_table(assay, "food")), [control])) is not None:
            return at
    if measure == "bites" and s.loc[s["condition"].isin([condition, control]), "bites"].sum() == 0:
        return Outcome(np.nan, np.nan, 0, None, verdict="not decidable",
                       reason=f"at a floor: no bite at all in {condition} or {control}")
    return paired_part(ctx, s, measure, condition, control, sign, family)


def _parts(ctx: Context, assay: str, control: str, specs, decides: bool = True,
           family: list[str] | None = None) -> list[Part]:
    """One paired part per (label, condition, measure, sign) of ``specs``."""
    stat = "median paired difference of the episode {m}, {c} minus {ctl}; Wilcoxon signed-rank, Holm"
    return [ctx.part(label, stat.format(m=measure, c=cond, ctl=control),
                     functools.partial(_vs_control, ctx, assay, cond, control, measure, sign, family), decides)
            for label, cond, measure, sign in specs]


def _tables(assays, tables=("episode_summary",)) -> list[str]:
    return ([analysis_table("behaviour", a, t) for a in assays for t in tables]
            + [assay_table(a, "food") for a in assays])


@claim("C10", "4A-F", "short-range ablations cut food; Knollenorgan ablation keeps food, raises EOD probability "
       "and biting, lowers spacing", _tables(("ablation4", "ablation1")))
def c10(ctx: Context) -> list[Part]:
    return (_parts(ctx, "ablation4", ALL_ON, [("group food, M off", M_OFF, FOOD, -1),
                                              ("group food, A off", A_OFF, FOOD, -1)])
            + _parts(ctx, "ablation1", ALL_ON, [("solo food, M off", M_OFF, FOOD, -1),
                                                ("solo food, A off", A_OFF, FOOD, -1)])
            + _parts(ctx, "ablation4", ALL_ON, [
                ("group food, K off (equivalent)", K_OFF, FOOD, 0),
                ("EOD probability, K off", K_OFF, "eod_probability", +1), ("bites, K off", K_OFF, "bites", +1),
                ("nearest-neighbour distance, K off", K_OFF, "mean_nn_dist_cm", -1)]))


# config/assay/collective.yaml: the clean gates, and the authors' self-only mode (own wall images kept)
GATES = ["self_only", "cons_only"]


@claim("C11", "4G,H", "self-only gating cuts food, cons-only does not; EOD lower in self-only, higher in cons-only",
       _tables(("collective",)))
def c11(ctx: Context) -> list[Part]:
    authors = [("food, self-only (authors' mode)", "self_only_authors", FOOD, -1),
               ("EOD probability, self-only (authors' mode)", "self_only_authors", "eod_probability", -1)]
    return (_parts(ctx, "collective", "control", [
        ("food, self-only", "self_only", FOOD, -1), ("food, cons-only (equivalent)", "cons_only", FOOD, 0),
        ("EOD probability, self-only", "self_only", "eod_probability", -1),
        ("EOD probability, cons-only", "cons_only", "eod_probability", +1)], family=GATES)
        + _parts(ctx, "collective", "control", authors, decides=False, family=["self_only_authors"]))


@claim("C12", "4I,J", "muting one agent cuts group food and raises spacing", _tables(("mute",)))
def c12(ctx: Context) -> list[Part]:
    # config/assay/mute.yaml: the Results' design (2 agents, uniform) decides; the Methods' (4, patchy) is beside it
    specs = [("group food", FOOD, -1), ("spacing", "mean_nn_dist_cm", +1)]
    return (_parts(ctx, "mute", "intact", [(f"{label}, 2 agents", "muted", m, s) for label, m, s in specs],
                   family=["muted"])
            + _parts(ctx, "mute", "intact4", [(f"{label}, 4 agents (Methods)", "muted4", m, s) for label, m, s in specs],
                     decides=False, family=["muted4"]))


NPATCH = re.compile(r"(iso|free)_(\d+)$")  # config/assay/npatch.yaml


def _episode_theil(ctx: Context, assay: str) -> pd.DataFrame:
    """Excess Theil T of every episode of ``assay`` (totals differ), with its summary columns."""
    per_agent = ctx.table(analysis_table("behaviour", assay, "food_per_agent"))
    return summary(ctx, assay).merge(excess_theil_per_episode(per_agent), on=["condition", "episode"])


def _npatch(ctx: Context) -> pd.DataFrame:
    """The N-patch sweep's episodes with ``series`` (iso, free), ``n`` and ``food_ratio``: iso food over the mean
    food of the free series at the same n (the authors' ratio per n)."""
    s = _episode_theil(ctx, "npatch")
    m = s["condition"].astype(str).str.extract(NPATCH)
    s = s.assign(series=m[0], n=pd.to_numeric(m[1]))
    free = s[s["series"] == "free"].groupby("n")[FOOD].mean()
    present(s, "series", ["iso", "free"], "N-patch episodes")
    return s.assign(food_ratio=s[FOOD] / s["n"].map(free).where(lambda v: v > 0))


@claim("C13", "4K-N", "patchy food yields more than uniform, Theil n.s.; more patches at fixed total food lower "
       "per-fish intake and inequality", _tables(("patchy4", "uniform4", "npatch"), ("episode_summary",
                                                                                   "food_per_agent")))
def c13(ctx: Context) -> list[Part]:
    def layouts() -> pd.DataFrame:
        both = [_episode_theil(ctx, a).assign(condition=a) for a in ("patchy4", "uniform4")]
        return pd.concat(both, ignore_index=True)

    def food() -> Outcome:
        return mann_whitney_part(ctx, layouts(), FOOD, "condition", "patchy4", "uniform4", +1)

    def theil() -> Outcome:
        d = layouts().dropna(subset=["excess_theil"])
        x, c = (d.loc[d["condition"] == g, "excess_theil"].to_numpy() for g in ("patchy4", "uniform4"))
        margin, how = margin_for(ctx, c, x)
        diff, p, p_equiv = welch_tost(x, c, margin)
        ci = ctx.ci(d, mean_diff("excess_theil", "condition", "patchy4", "uniform4"))
        return Outcome(diff, p, len(d), 0, ci, f"margin {margin:.3g} = {how}", p_equiv=p_equiv, margin=margin)

    def sweep(series: str, value: str) -> Outcome:
        return spearman_part(ctx, _npatch(ctx).query("series == @series"), "n", value, -1)
    rho = "Spearman rho of the {} episodes' {} against the patch count n"
    return [ctx.part("food, patchy vs uniform", "median episode food patchy4 minus uniform4; Mann-Whitney", food),
            ctx.part("excess Theil, patchy vs uniform (equivalent)", "mean episode Theil T above its equal-share "
                     "null at the episode's total, patchy4 minus uniform4; Welch t-test and TOST", theil),
            ctx.part("iso/free food vs n", rho.format("iso", "food over the free series' mean food at n"),
                     functools.partial(sweep, "iso", "food_ratio")),
            ctx.part("iso excess Theil vs n", rho.format("iso", "excess Theil T"),
                     functools.partial(sweep, "iso", "excess_theil")),
            ctx.part("free excess Theil vs n", rho.format("free", "excess Theil T"),
                     functools.partial(sweep, "free", "excess_theil"))]
