"""The claims of Fig 4 (C10-C13): ablations, collective sensing, muting, food layouts.

Conditions of one assay
share their episode seeds, so they are compared paired over episodes with a
Holm correction over the conditions compared with the same control; "no
difference" parts are decided against delta as an equivalence margin; food parts are not decidable while
the control eats every pellet; Theil T is compared above its equal-share null
where totals differ (the rules: docs/claims/index.md).

Condition names are those of ``config/assay/<assay>.yaml``.
"""

from __future__ import annotations

import functools
import re

import numpy as np
import pandas as pd

from ..layout import analysis_table
from ..senses import SENSES, condition_name
from .context import Context, claim
from .parts import ceiling, mann_whitney_part, paired_part, present, spearman_part
from .statistics import excess_theil_per_episode, welch_difference
from .verdicts import Outcome, Part

# ablation conditions are named by the receptor classes left on (config/assay/ablation4.yaml): all on, then each off
ALL_ON = condition_name(SENSES)
M_OFF, A_OFF, K_OFF = (condition_name(s for s in SENSES if s is not off) for off in SENSES)
FOOD = "food_total"


def summary(ctx: Context, assay: str) -> pd.DataFrame:
    """The behaviour analysis's episode summary of ``assay``: one row per (condition, episode)."""
    return ctx.table(analysis_table("behaviour", assay, "episode_summary"))


def _vs_control(ctx: Context, assay: str, condition: str, control: str, measure: str, sign: int,
                family: list[str]) -> Outcome:
    """A paired part of ``assay`` (:func:`~efish.claims.parts.paired_part`, Holm over ``family``); a food part is
    not decidable when the control is at a ceiling."""
    s = summary(ctx, assay)
    s = s[s["condition"].isin([*family, control])]
    if measure == FOOD:
        if (at := ceiling(ctx, s, [control])) is not None:
            return at
    return paired_part(ctx, s, measure, condition, control, sign, family)


#: A paired part: its label, assay, condition, measure and the paper's sign.
Spec = tuple[str, str, str, str, int]


def _parts(ctx: Context, control: str, specs: list[Spec], decides: bool = True) -> list[Part]:
    """One paired part per spec against ``control``. Holm runs over the comparisons the parts test: one family per
    (assay, measure), the conditions these specs compare with the control on that measure."""
    families: dict[tuple[str, str], list[str]] = {}
    for _, assay, cond, measure, _ in specs:
        families.setdefault((assay, measure), []).append(cond)
    stat = ("Hodges-Lehmann estimate of the paired differences of the episode {m}, {c} minus {ctl} ({a}); Wilcoxon "
            "signed-rank, Holm over {k}")
    return [ctx.part(label, stat.format(m=measure, c=cond, ctl=control, a=assay, k=len(families[assay, measure])),
                     functools.partial(_vs_control, ctx, assay, cond, control, measure, sign,
                                       families[assay, measure]), decides)
            for label, assay, cond, measure, sign in specs]


def _tables(assays, tables=("episode_summary",)) -> list[str]:
    return [analysis_table("behaviour", a, t) for a in assays for t in tables]


@claim("C10", "4A-F", "short-range ablations cut food; Knollenorgan ablation keeps food, raises EOD probability "
       "and biting, lowers spacing", _tables(("ablation4", "ablation1")))
def c10(ctx: Context) -> list[Part]:
    return _parts(ctx, ALL_ON, [
        ("group food, M off", "ablation4", M_OFF, FOOD, -1), ("group food, A off", "ablation4", A_OFF, FOOD, -1),
        ("solo food, M off", "ablation1", M_OFF, FOOD, -1), ("solo food, A off", "ablation1", A_OFF, FOOD, -1),
        ("group food, K off (equivalent)", "ablation4", K_OFF, FOOD, 0),
        ("EOD probability, K off", "ablation4", K_OFF, "eod_probability", +1),
        ("bites, K off", "ablation4", K_OFF, "bites", +1),
        ("nearest-neighbour distance, K off", "ablation4", K_OFF, "mean_nn_dist_cm", -1)])


@claim("C11", "4G,H", "self-only gating cuts food, cons-only does not; EOD lower in self-only, higher in cons-only",
       _tables(("collective",)))
def c11(ctx: Context) -> list[Part]:
    # the clean gates decide; the authors' self-only mode (own wall images kept) is beside them, its own family
    gates = [("food, self-only", "self_only", FOOD, -1), ("food, cons-only (equivalent)", "cons_only", FOOD, 0),
             ("EOD probability, self-only", "self_only", "eod_probability", -1),
             ("EOD probability, cons-only", "cons_only", "eod_probability", +1)]
    authors = [("food, self-only (authors' mode)", "self_only_authors", FOOD, -1),
               ("EOD probability, self-only (authors' mode)", "self_only_authors", "eod_probability", -1)]
    return (_parts(ctx, "control", [(label, "collective", c, m, s) for label, c, m, s in gates])
            + _parts(ctx, "control", [(label, "collective", c, m, s) for label, c, m, s in authors], decides=False))


@claim("C12", "4I,J", "muting one agent cuts group food and raises spacing", _tables(("mute",)))
def c12(ctx: Context) -> list[Part]:
    # config/assay/mute.yaml: the Results' design (2 agents, uniform) decides; the Methods' (4, patchy) is beside it
    specs = [("group food", FOOD, -1), ("spacing", "mean_nn_dist_cm", +1)]
    return (_parts(ctx, "intact", [(f"{label}, 2 agents", "mute", "muted", m, s) for label, m, s in specs])
            + _parts(ctx, "intact4", [(f"{label}, 4 agents (Methods)", "mute", "muted4", m, s)
                                      for label, m, s in specs], decides=False))


NPATCH = re.compile(r"(iso|free)_(\d+)$")  # config/assay/npatch.yaml


def _episode_theil(ctx: Context, assay: str) -> pd.DataFrame:
    """Excess Theil T and per-fish food of every episode of ``assay`` (totals differ), with its summary columns."""
    per_agent = ctx.table(analysis_table("behaviour", assay, "food_per_agent"))
    s = summary(ctx, assay).merge(excess_theil_per_episode(per_agent), on=["condition", "episode"])
    agents = per_agent.groupby(["condition", "episode"])["food_eaten"].size().rename("agents").reset_index()
    s = s.merge(agents, on=["condition", "episode"])
    return s.assign(food_per_fish=s[FOOD] / s["agents"]).drop(columns="agents")


def _npatch(ctx: Context) -> pd.DataFrame:
    """The N-patch sweep's episodes with ``series`` (iso: fixed total food; free: food grows with n) and ``n``."""
    s = _episode_theil(ctx, "npatch")
    m = s["condition"].astype(str).str.extract(NPATCH)
    s = s.assign(series=m[0], n=pd.to_numeric(m[1]))
    present(s, "series", ["iso", "free"], "N-patch episodes")
    return s


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
        diff, p, ci = welch_difference(x, c, ctx.level())
        return Outcome(diff, p, len(d), 0, ci, ci_method=f"inverts Welch's t-test, level {ctx.level():.3g}",
                       reference=float(np.median(c)) if c.size else np.nan)

    def sweep(series: str, value: str) -> Outcome:
        return spearman_part(ctx, _npatch(ctx).query("series == @series"), "n", value, -1)
    rho = "Spearman rho of the {} episodes' {} against the patch count n"
    return [ctx.part("food, patchy vs uniform", "Hodges-Lehmann shift of the episode food, patchy4 minus uniform4; "
                     "Mann-Whitney", food),
            ctx.part("excess Theil, patchy vs uniform (equivalent)", "mean episode Theil T above its equal-share "
                     "null at the episode's total, patchy4 minus uniform4; Welch t-test", theil),
            ctx.part("iso per-fish food vs n", rho.format("iso (fixed total food)", "food per fish"),
                     functools.partial(sweep, "iso", "food_per_fish")),
            ctx.part("free per-fish food vs n", rho.format("free", "food per fish"),
                     functools.partial(sweep, "free", "food_per_fish"), decides=False),
            ctx.part("iso excess Theil vs n", rho.format("iso", "excess Theil T"),
                     functools.partial(sweep, "iso", "excess_theil")),
            ctx.part("free excess Theil vs n", rho.format("free", "excess Theil T"),
                     functools.partial(sweep, "free", "excess_theil"))]
