"""The claims of Fig 5 (C14-C16): the intruder at one patch, the bot, chasing and biting bouts.

Condition names are those of ``config/assay/<assay>.yaml``; who is A, B, the bot
or alone, and at which size, is read from the conditions the assay recorded.
"""

from __future__ import annotations

import dataclasses
import functools

import numpy as np
import pandas as pd

from ..analysis.onepatch import REACH_CONTRASTS, bot_reach_counts, matched_alone, roles, social_conditions
from ..layout import analysis_table, assay_table
from .context import Context, claim
from .fig3 import size_roles
from .parts import (
    from_row,
    mann_whitney_part,
    one_sample_part,
    paired_difference,
    per_episode,
    present,
    spearman_part,
    stat_row,
)
from .statistics import mean_diff
from .verdicts import Outcome, Part

ONEPATCH_FOOD = analysis_table("behaviour", "onepatch", "food_per_agent")
ONEPATCH_CONDITIONS = assay_table("onepatch", "conditions")


@claim("C14", "5E-H", "intruder B eats more with A present than alone; A is unaffected; B does better when larger",
       [ONEPATCH_FOOD, ONEPATCH_CONDITIONS])
def c14(ctx: Context) -> list[Part]:
    configs = ctx.recorded("onepatch")  # who is A, B or alone, and their sizes
    matched = matched_alone(configs)

    def people() -> pd.DataFrame:
        """Agent-episodes with role (A, B) and setting (a social condition or alone)."""
        return roles(ctx.table(ONEPATCH_FOOD), configs)

    def b_social(social: str) -> Outcome:
        """B with A in ``social`` vs B alone at the same size (the matched alone condition)."""
        if ("B", social) not in matched:
            raise ValueError(f"no B alone condition at B's size in {social}")
        b = people()
        b = b[(b["role"] == "B") & b["condition"].isin([social, matched["B", social]])]
        alone = b.loc[b["setting"] == "alone", "food_eaten"].dropna()
        if len(alone) and not alone.any():  # a floor (rule 5): "more with A" is all B alone could show
            return Outcome(np.nan, np.nan, len(b), +1, verdict="not decidable",
                           reason=f"at a floor: B alone ({matched['B', social]}) ate nothing in any of its "
                                  f"{len(alone)} episodes, so only more food with A could appear")
        return mann_whitney_part(ctx, b, "food_eaten", "setting", social, "alone", +1)

    def a_unaffected() -> Outcome:
        """A with B (every size class) vs A alone at the same sizes: the two samples have one size mix."""
        controls = [alone for (role, _), alone in matched.items() if role == "A"]
        a = people()
        a = a[(a["role"] == "A") & ((a["setting"] != "alone") | a["condition"].isin(controls))]
        a = a.assign(setting=np.where(a["setting"] == "alone", "alone", "social"))
        return mann_whitney_part(ctx, a, "food_eaten", "setting", "social", "alone", 0)

    def b_size() -> Outcome:
        b = people().query("role == 'B' and setting != 'alone'")
        return spearman_part(ctx, b, "size", "food_eaten", +1)
    stat = "Hodges-Lehmann shift of the food of B with A ({}) against B alone at B's size; Mann-Whitney"
    return ([ctx.part(f"B social, {c}", stat.format(c), functools.partial(b_social, c))
             for c in social_conditions(configs)]
            + [ctx.part("A social vs alone (equivalent)", "Hodges-Lehmann shift of the food of A with B against A alone at A's sizes "
                        "(size classes pooled, one alone condition per class); Mann-Whitney", a_unaffected),
               ctx.part("B food vs B size", "Spearman rho of B's food against B's size over the social conditions",
                        b_size)])


BOT_REACH = analysis_table("onepatch", "bot", "reach_rates")
BOT_REACH_TESTS = analysis_table("onepatch", "bot", "reach_tests")
BOT_CONDITIONS = assay_table("bot", "conditions")


def _reach(ctx: Context, contrast: str) -> Outcome:
    """The onepatch analysis's Fisher row of B's reach rate (pooled episodes); interval over episodes."""
    row = stat_row(ctx.table(BOT_REACH_TESTS), contrast=contrast)
    a, b = REACH_CONTRASTS[contrast]
    counts = bot_reach_counts(ctx.table(BOT_REACH), ctx.recorded("bot"), contrast)
    present(counts.reset_index(), "group", [a, b], "bot episodes")
    # one row per episode (reached or not): the reach table's counts, resampled as episodes
    per = pd.DataFrame([{"condition": g, "episode": i, "reached": i < k}
                        for g, (k, n) in counts.iterrows() for i in range(n)])
    ci = ctx.ci(per.assign(reached=per["reached"].astype(float)), mean_diff("reached", "condition", a, b))
    return dataclasses.replace(from_row(row, +1, ci), n=int(counts["n_episodes"].sum()))


@claim("C15", "5I,J", "B reaches the patch more often when the bot is frozen, and when it emits than when silent",
       [BOT_REACH, BOT_REACH_TESTS, BOT_CONDITIONS])
def c15(ctx: Context) -> list[Part]:
    return [ctx.part("frozen vs moving bot", "B's reach rate with the bot frozen minus moving; Fisher exact "
                     "(onepatch reach_tests)", functools.partial(_reach, ctx, "mobility")),
            ctx.part("emitting vs silent bot", "B's reach rate with bot EOD rate > 0 minus rate 0; Fisher exact "
                     "(onepatch reach_tests)", functools.partial(_reach, ctx, "eod"))]


SQUARE2_BITE_RATES = analysis_table("interactions", "square2", "bite_rate_episodes")


def _confronting(ctx: Context) -> Outcome:
    """Per-episode bite rate of confronting pair-steps minus the next-highest class, paired Wilcoxon over episodes
    (the interactions analysis's bite_rate_episodes)."""
    per = ctx.table(SQUARE2_BITE_RATES).dropna(subset=["label", "rate"])
    per = per[per["label"] != "undefined"]
    pooled = per.groupby("label")[["bites", "n_steps"]].sum()
    if "confronting" not in pooled.index or len(pooled) < 2:
        raise ValueError("no confronting pair-step, or no other class, within range")
    other = (pooled["bites"] / pooled["n_steps"]).drop("confronting").idxmax()
    # episodes where both classes occur within range: each episode is one paired unit, never pooled steps
    both = per[per["label"].isin(["confronting", other])]
    both = both[both.groupby(["condition", "episode"])["label"].transform("nunique") == 2]
    out = paired_difference(ctx, both, "confronting", other, value="rate", key="label")
    reference = float(both.loc[both["label"] == other, "rate"].median())  # the next-highest class's median rate
    return dataclasses.replace(out, reason="; ".join(r for r in (out.reason, f"next-highest class: {other}") if r),
                               reference=reference)


@claim("C16", "5K-P", "larger agents chase; biting peaks early in bouts; confronting bouts bite most",
       [analysis_table("interactions", "square2", t) for t in ("size_tests", "chase_sizes", "bite_timing",
                                                               "bite_rate_episodes")])
def c16(ctx: Context) -> list[Part]:
    def timing() -> Outcome:
        """Per episode, the median phase of its bites within their bouts (the paper: the median bite time), tested
        across episodes (rule 1): an episode's bites share its pair and bouts, so one bite-heavy episode is one
        unit, not many (the third audit: 22 of 26 bites from one of 3 episodes decided the part at p 0.012)."""
        bites = ctx.table(analysis_table("interactions", "square2", "bite_timing")).dropna(subset=["phase"])
        per = per_episode(bites, "phase", lambda d: float(d["phase"].median()))
        return one_sample_part(ctx, per, "phase", 0.5, -1)
    return [ctx.part("chaser larger", "Hodges-Lehmann estimate over episodes of the mean chaser minus chased size "
                     "of the episode's chasing bouts (square2); Wilcoxon signed-rank",
                     functools.partial(size_roles, ctx, "square2", "chase_sizes")),
            ctx.part("bites early", "Hodges-Lehmann estimate over episodes of the median normalised bite time in its "
                     "bout minus 0.5 (square2); Wilcoxon signed-rank", timing),
            ctx.part("confronting bites most", "Hodges-Lehmann estimate over episodes of the bite rate per pair-step within range, "
                     "confronting minus the next-highest class; Wilcoxon signed-rank", functools.partial(_confronting,
                                                                                                       ctx))]
