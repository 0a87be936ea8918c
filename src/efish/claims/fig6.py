"""The claims of Fig 6 (C17-C21): the hidden dynamics: dimensionality, decoding, shared components, power.

Decoding rule (docs/claims/index.md#rule-7): a hidden state is decoded against
the world it observed, never ranked against copies of its own input (its last
action, its size, summaries of its sensor inputs). C18 and C19 read the
dynamics analysis's per-episode decoding skill, the numbers of Fig 6D-F.
"""

from __future__ import annotations

import dataclasses

import numpy as np
import pandas as pd

from ..analysis._tables import AGENT_EPISODE
from ..analysis.decoding import FOOD_TARGETS, SENSED_TARGETS
from ..analysis.dynamics_tests import groupsize_parts
from ..layout import analysis_table, assay_table
from .context import Context, claim
from .fig2 import HOMING_ELECTRIC
from .intervals import smallest_p_signed_rank
from .parts import decoded, one_sample_part, paired_difference, per_episode, spearman_part
from .statistics import interaction_slope, rho_of
from .verdicts import Outcome, Part


@claim("C17", "6A-C", "hidden dynamics are low-dimensional; D_eff grows with group size only with Knollenorgans",
       [*(analysis_table("dynamics", a, "dimensionality") for a in ("patchy4", "groupsize")),
        assay_table("groupsize", "conditions")])
def c17(ctx: Context) -> list[Part]:
    a = ctx.cfg.analysis

    def low() -> Outcome:
        # D_eff as a share of the acting policy's own width (the table's n_units), not of this config's train.hidden
        dims = ctx.table(analysis_table("dynamics", "patchy4", "dimensionality"))
        dims = dims.assign(fraction=dims["d_eff"] / dims["n_units"]).dropna(subset=["fraction"])
        return one_sample_part(ctx, per_episode(dims, "fraction"), "fraction", a.claims_deff_fraction, -1)

    def groupsize_episodes() -> pd.DataFrame:
        """D_eff averaged over the agents of each groupsize episode (the episode is the unit)."""
        dims = groupsize_parts(ctx.table(analysis_table("dynamics", "groupsize", "dimensionality")),
                               ctx.recorded("groupsize"))
        return (dims.groupby(["condition", "episode", "n_agents", "knollenorgans"], as_index=False)["d_eff"].mean()
                .dropna(subset=["d_eff"]))

    def grows() -> Outcome:
        return spearman_part(ctx, groupsize_episodes().query("knollenorgans == 'K'"), "n_agents", "d_eff", +1)

    def interaction() -> Outcome:
        d = groupsize_episodes()
        on = (d["knollenorgans"] == "K").to_numpy(np.float64)
        b, p, n, ci = interaction_slope(d["n_agents"], d["d_eff"], on, 1 - ctx.level())
        return Outcome(b, p, n, +1, ci, ci_method=f"inverts the t-test, level {ctx.level():.3g}")
    return [ctx.part("low-dimensional", "Hodges-Lehmann estimate over episodes of the agents' mean D_eff / hidden units "
                     f"(n_units) minus {a.claims_deff_fraction} (patchy4); Wilcoxon", low),
            ctx.part("D_eff grows with N, K on", "Spearman rho(mean D_eff of the episode, N), Knollenorgans on "
                     "(groupsize)", grows),
            ctx.part("growth larger with K than without", "OLS slope of episode D_eff on N with Knollenorgans on "
                     "minus off (the N x K interaction of D_eff ~ N * K over episodes); t-test", interaction)]


HOMING_DECODING = analysis_table("dynamics", "homing", "decoding_episodes")


@claim("C18", "6D", "the Knollenorgan error angle is decoded better than the straight bearing to the target",
       [HOMING_DECODING])
def c18(ctx: Context) -> list[Part]:
    def compute() -> Outcome:
        skills = decoded(ctx, HOMING_DECODING, ["err_knollen_rad", "bearing_agent_rad"], condition=HOMING_ELECTRIC)
        out = paired_difference(ctx, skills, "err_knollen_rad", "bearing_agent_rad")
        # faithful to the paper, and partly mechanical: the binarised Knollenorgan signs encode the target field's
        # direction relative to the body, while the straight bearing is not observed
        note = "partly by construction: the Knollenorgan signs encode the field direction, the bearing is unobserved"
        return dataclasses.replace(out, reason="; ".join(r for r in (out.reason, note) if r))
    return [ctx.part("err vs bearing", "Hodges-Lehmann estimate over episodes of held-out decoding skill (1 - SSE / SSE "
                     "of the training mean, dynamics decoding_episodes of the homer) of err_knollen minus bearing to "
                     "the target; Wilcoxon", compute)]


#: The world variables of Fig 6E that claim C19 ranks (docs/claims/index.md#c19), all sensed
#: (efish.analysis.decoding.SENSED_TARGETS): the nearest-agent distance and the Knollenorgan feature (agents in
#: Knollenorgan range; with wide2's two agents, also whether one is) the paper finds best ...
AGENT_FEATURES = ("dist_agent_cm", "n_agents_100cm")
#: ... and the others it ranks them against: the Mormyromast field at the body centre (log10, computed from the
#: scene) and the wall distance, the competitors the claim's statement of Fig 6E names. Bearings, sizes, food and
#: the Ampullary field are decoded for Fig 6E and listed in the reason, not ranked here.
OTHER_FEATURES = ("log_morm_field", "dist_wall_cm")
WIDE2_DECODING = analysis_table("dynamics", "wide2", "decoding")
WIDE2_DECODED = analysis_table("dynamics", "wide2", "decoding_episodes")
WIDE2_FOOD_DECODED = analysis_table("dynamics", "wide2", "food_decoding_episodes")


def _listed(skills: pd.Series) -> str:
    """Decoding skills, best first, as the reason lists them ("dist_agent_cm 0.85, ...")."""
    return ", ".join(f"{k} {v:.2f}" for k, v in skills.sort_values(ascending=False).items())


@claim("C19", "6E,F", "nearest-agent distance and Knollenorgan features decode best; food variables decode better "
       "when food is in range", [WIDE2_DECODING, WIDE2_DECODED, WIDE2_FOOD_DECODED])
def c19(ctx: Context) -> list[Part]:
    near_cm = ctx.cfg.analysis.claims_food_near_cm

    def ranking() -> Outcome:
        """The best agent feature against the best other ranked variable (:data:`OTHER_FEATURES`), by Fig 6E's
        pooled skill (dynamics decoding; distances decoded as log10), paired over the episodes of
        decoding_episodes."""
        summary = ctx.table(WIDE2_DECODING)
        sensed = summary[summary["target"].isin(list(SENSED_TARGETS))].groupby("target")["skill"].mean().dropna()
        skill = sensed.reindex([*AGENT_FEATURES, *OTHER_FEATURES]).dropna()
        ours, rest = skill.reindex(AGENT_FEATURES).dropna(), skill.reindex(OTHER_FEATURES).dropna()
        if ours.empty or rest.empty:
            raise ValueError(f"no agent feature {list(AGENT_FEATURES)} or no other ranked variable "
                             f"{list(OTHER_FEATURES)} with a finite decoding skill")
        best, other = ours.idxmax(), rest.idxmax()
        out = paired_difference(ctx, decoded(ctx, WIDE2_DECODED, [best, other]), best, other)
        notes = (out.reason, f"skill (Fig 6E): {_listed(skill)}",
                 f"not ranked: {_listed(sensed.drop(skill.index))}" if len(sensed) > len(skill) else "")
        return dataclasses.replace(out, reason="; ".join(r for r in notes if r))

    def food() -> Outcome:
        """Per episode, the mean skill of the food variables near minus far (dynamics food_decoding_episodes)."""
        skills = decoded(ctx, WIDE2_FOOD_DECODED, list(FOOD_TARGETS))
        per = skills.groupby(["condition", "episode", "food"], as_index=False)["skill"].mean()
        return paired_difference(ctx, per, "near", "far", key="food")
    return [ctx.part("agent features best", "Hodges-Lehmann estimate over episodes of held-out skill of the best agent or "
                     "Knollenorgan feature minus the best of the Mormyromast field and the wall distance (wide2, "
                     "dynamics decoding_episodes; distances as log10; readouts of the network's own input "
                     "excluded); Wilcoxon", ranking),
            ctx.part("food near > far", f"Hodges-Lehmann estimate over episodes of held-out skill of food distance and bearing, "
                     f"nearest pellet within {near_cm:g} cm minus beyond (dynamics food_decoding_episodes); Wilcoxon",
                     food)]


WIDE2_COLLAPSE = analysis_table("dynamics", "wide2", "plsc_collapse")
WIDE2_PLSC_EPISODES = analysis_table("dynamics", "wide2", "plsc_episodes")


@claim("C20", "6G,H", "the PLSC first-component correlation falls with pair distance; significant dimensions "
       "collapse beyond 100 cm", [WIDE2_PLSC_EPISODES, WIDE2_COLLAPSE])
def c20(ctx: Context) -> list[Part]:
    def falls() -> Outcome:
        """Per episode, the Spearman rho of its bins' first-component correlation (dynamics plsc_episodes) against
        the bin."""
        rows = ctx.table(WIDE2_PLSC_EPISODES)
        if rows["episode"].isna().all():
            raise ValueError("; ".join(sorted({r for r in rows["reason"] if isinstance(r, str) and r}))
                             or f"no episode in {WIDE2_PLSC_EPISODES}")
        per = per_episode(rows.dropna(subset=["r_1"]), "rho", rho_of("bin", "r_1"))
        return one_sample_part(ctx, per, "rho", 0.0, -1)

    def collapse() -> Outcome:
        """The dynamics analysis's collapse test: calibrated shared dimensions far minus near at equal steps, a
        permutation p over whole episodes (analysis/plsc_tests.py)."""
        row = ctx.table(WIDE2_COLLAPSE).iloc[0]
        reason = str(row["reason"]) if isinstance(row["reason"], str) else ""
        if not np.isfinite(row["p"]):
            raise ValueError(reason or "no collapse test result")
        note = (f"shared dimensions {row['near_significant']:.3g} near, {row['far_significant']:.3g} far at "
                f"{int(row['n_steps'])} steps each")
        return Outcome(float(row["effect"]), float(row["p"]), int(row["n_episodes"]), -1,
                       reason="; ".join(r for r in (note, reason) if r),
                       p_floor=smallest_p_signed_rank(int(row["n_episodes"])))
    return [ctx.part("r1 falls with distance", "Hodges-Lehmann estimate over episodes of the Spearman rho of the "
                     "episode's PLSC first-component correlation against its distance bin (wide2); Wilcoxon", falls),
            ctx.part("collapse beyond the last edge", "calibrated shared dimensions (step-down, episode-swap null) "
                     "beyond the last edge minus within the first, at equal steps per episode; permutation test "
                     "over whole episodes (dynamics plsc_collapse, wide2)", collapse)]


POWER_NEAR_FAR = analysis_table("dynamics", "wide2", "power_near_far")
POWER_ROLES = analysis_table("dynamics", "wide2", "power_roles")


@claim("C21", "6I,J", "a nearby conspecific lowers wideband power; smaller agents carry more",
       [POWER_NEAR_FAR, POWER_ROLES])
def c21(ctx: Context) -> list[Part]:
    a = ctx.cfg.analysis

    def near_far() -> Outcome:
        """Per episode, its agents' mean wideband power far minus near (power_near_far), across episodes."""
        wide = ctx.table(POWER_NEAR_FAR).pivot(index=AGENT_EPISODE, columns="where", values="wideband_power")
        wide = wide.reindex(columns=["near", "far"])
        both = wide[["near", "far"]].dropna()
        diff = (both["far"] - both["near"]).rename("diff").reset_index()
        out = one_sample_part(ctx, per_episode(diff, "diff"), "diff", 0.0, +1)
        near = per_episode(both["near"].rename("near").reset_index(), "near")["near"]
        return dataclasses.replace(out, reference=float(near.median()))  # the episodes' median power near

    def smaller() -> Outcome:
        """Per episode, the smaller agent's wideband power minus the larger's (paired within the episode; dynamics
        power_roles)."""
        d = ctx.table(POWER_ROLES).dropna(subset=["wideband_power"])
        by_role = d.pivot_table(index=["condition", "episode"], columns="role", values="wideband_power")
        by_role = by_role.reindex(columns=["smaller", "larger"]).dropna()
        diff = (by_role["smaller"] - by_role["larger"]).rename("diff").reset_index()
        out = one_sample_part(ctx, diff, "diff", 0.0, +1)
        return dataclasses.replace(out, reference=float(by_role["larger"].median()))  # the larger agent's median
    return [ctx.part("far > near", f"Hodges-Lehmann estimate over episodes of the agents' mean wideband power with "
                     f"the conspecific beyond {a.claims_far_cm:g} cm minus within {a.claims_near_cm:g} cm; Wilcoxon "
                     "signed-rank", near_far),
            ctx.part("smaller carries more", "Hodges-Lehmann estimate over episodes of the wideband power of the "
                     "smaller minus the larger agent (wide2); Wilcoxon signed-rank", smaller)]
