"""The claims of Fig 6 (C17-C21): the hidden dynamics: dimensionality, decoding, shared components, power.

Decoding rule (docs/claims/index.md): a hidden state is decoded against the
world it observed, never against the policy's own outputs or a per-agent
constant.
"""

from __future__ import annotations

import dataclasses

import numpy as np
import pandas as pd

from ..analysis._tables import AGENT_EPISODE, values_of
from ..analysis.decoding import heldout_skill
from ..analysis.dynamics import DECODE_TARGETS, plsc
from ..analysis.dynamics_tests import groupsize_parts, smaller_larger
from ..layout import analysis_table, assay_table
from .context import Context, claim
from .fig2 import HOMING_ELECTRIC, HOMING_STEPS
from .fig3 import WIDE2_CONDITIONS, WIDE2_STEPS
from .intervals import smallest_p_signed_rank
from .parts import joined, one_sample_part, paired_difference, per_episode, spearman_part
from .statistics import interaction_slope, rho_of
from .verdicts import Outcome, Part

HOMING_HIDDEN, WIDE2_HIDDEN = assay_table("homing", "hidden"), assay_table("wide2", "hidden")


@claim("C17", "6A-C", "hidden dynamics are low-dimensional; D_eff grows with group size only with Knollenorgans",
       [analysis_table("dynamics", a, "dimensionality") for a in ("patchy4", "groupsize")])
def c17(ctx: Context) -> list[Part]:
    a, width = ctx.cfg.analysis, ctx.cfg.train.hidden

    def low() -> Outcome:
        dims = ctx.table(analysis_table("dynamics", "patchy4", "dimensionality"))
        dims = dims.assign(fraction=dims["d_eff"] / width).dropna(subset=["fraction"])
        return one_sample_part(ctx, per_episode(dims, "fraction"), "fraction", a.claims_deff_fraction, -1)

    def groupsize_episodes() -> pd.DataFrame:
        """D_eff averaged over the agents of each groupsize episode (the episode is the unit)."""
        dims = groupsize_parts(ctx.table(analysis_table("dynamics", "groupsize", "dimensionality")))
        return (dims.groupby(["condition", "episode", "n_agents", "knollenorgans"], as_index=False)["d_eff"].mean()
                .dropna(subset=["d_eff"]))

    def grows() -> Outcome:
        return spearman_part(ctx, groupsize_episodes().query("knollenorgans == 'K'"), "n_agents", "d_eff", +1)

    def interaction() -> Outcome:
        d = groupsize_episodes()
        on = (d["knollenorgans"] == "K").to_numpy(np.float64)
        b, p, n, ci = interaction_slope(d["n_agents"], d["d_eff"], on, ctx.cfg.analysis.claims_alpha)
        return Outcome(b, p, n, +1, ci, ci_method="inverts the t-test")
    return [ctx.part("low-dimensional", f"Hodges-Lehmann estimate over episodes of the agents' mean D_eff / width ({width}) "
                     f"minus {a.claims_deff_fraction} (patchy4); Wilcoxon", low),
            ctx.part("D_eff grows with N, K on", "Spearman rho(mean D_eff of the episode, N), Knollenorgans on "
                     "(groupsize)", grows),
            ctx.part("growth larger with K than without", "OLS slope of episode D_eff on N with Knollenorgans on "
                     "minus off (the N x K interaction of D_eff ~ N * K over episodes); t-test", interaction)]


@claim("C18", "6D", "the Knollenorgan error angle is decoded better than the straight bearing to the target",
       [HOMING_HIDDEN, HOMING_STEPS])
def c18(ctx: Context) -> list[Part]:
    def compute() -> Outcome:
        j, h = joined(ctx, HOMING_HIDDEN, HOMING_STEPS, ["err_knollen_rad", "bearing_agent_rad"])
        j = j[(j["condition"] == HOMING_ELECTRIC) & np.isfinite(j["err_knollen_rad"])]  # the homer's steps
        if j.empty:
            raise ValueError("no electric homing step with a Knollenorgan error angle and a hidden state")
        skills = heldout_skill(j[h].to_numpy(), {"err_knollen_rad": (j["err_knollen_rad"].to_numpy(), True),
                                                 "bearing_agent_rad": (j["bearing_agent_rad"].to_numpy(), True)},
                               j["episode"].to_numpy(), ctx.cfg.analysis.decode_folds)
        out = paired_difference(ctx, skills, "err_knollen_rad", "bearing_agent_rad")
        # faithful to the paper, and partly mechanical: the binarised Knollenorgan signs encode the target field's
        # direction relative to the body, while the straight bearing is not observed
        note = "partly by construction: the Knollenorgan signs encode the field direction, the bearing is unobserved"
        return dataclasses.replace(out, reason="; ".join(r for r in (out.reason, note) if r))
    return [ctx.part("err vs bearing", "Hodges-Lehmann estimate over episodes of held-out decoding skill (1 - MSE / MSE of the "
                     "train mean) of err_knollen minus bearing to the target; Wilcoxon", compute)]


#: Fig 6E's sensed variables (decoding rule: never the policy's own outputs or the agent's constant size), and
#: among them the agent and Knollenorgan features the paper finds best.
SENSED = {"dist_agent_cm": False, "knollen_spikes": False, "n_agents_100cm": False, "log_morm_sensed": False,
          "dist_wall_cm": False}
AGENT_FEATURES = ("dist_agent_cm", "knollen_spikes", "n_agents_100cm")
FOOD_FEATURES = ("dist_food_cm", "bearing_food_rad")


@claim("C19", "6E,F", "nearest-agent distance and Knollenorgan features decode best; food variables decode better "
       "when food is in range", [WIDE2_HIDDEN, WIDE2_STEPS, WIDE2_CONDITIONS])
def c19(ctx: Context) -> list[Part]:
    folds = ctx.cfg.analysis.decode_folds
    near_cm = ctx.cfg.analysis.claims_food_near_cm

    def ranking() -> Outcome:
        missing = [c for c in SENSED if c not in ctx.table(WIDE2_STEPS).columns]
        if missing:
            raise ValueError(f"the wide2 steps table lacks the sensed variables {missing}: rerun the assay")
        j, h = joined(ctx, WIDE2_HIDDEN, WIDE2_STEPS, list(SENSED))
        # a step where no Mormyromast reads above E_min is recorded as NaN; the channel then delivers its floor
        # (every normalised reading 0), so it is decoded as log10 E_min there (the condition's, as wide2 recorded
        # it): every variable on the same steps
        e_min = {c: cfg.sensors.mormyromast.e_min for c, cfg in ctx.recorded("wide2").items()}
        floor = pd.Series(np.log10(values_of(e_min, j["condition"])), index=j.index)
        j["log_morm_sensed"] = j["log_morm_sensed"].fillna(floor)
        j = j[np.isfinite(j[list(SENSED)].astype(np.float64)).all(axis=1)]
        skills = heldout_skill(j[h].to_numpy(), {c: (j[c].to_numpy(), SENSED[c]) for c in SENSED},
                               j["episode"].to_numpy(), folds)
        mean = skills.groupby("target")["skill"].mean()
        ours, rest = mean.reindex(AGENT_FEATURES).dropna(), mean.drop(list(AGENT_FEATURES), errors="ignore")
        if ours.empty or rest.empty:
            raise ValueError("no agent or no other sensed variable with a finite decoding skill")
        out = paired_difference(ctx, skills, ours.idxmax(), rest.idxmax())
        ranked = ", ".join(f"{k} {v:.2f}" for k, v in mean.sort_values(ascending=False).items())
        return dataclasses.replace(out, reason="; ".join(r for r in (out.reason, f"mean skill: {ranked}") if r))

    def food() -> Outcome:
        j, h = joined(ctx, WIDE2_HIDDEN, WIDE2_STEPS, list(FOOD_FEATURES))
        j = j.dropna(subset=list(FOOD_FEATURES))
        parts = []
        for name, sub in (("near", j[j["dist_food_cm"] <= near_cm]), ("far", j[j["dist_food_cm"] > near_cm])):
            s = heldout_skill(sub[h].to_numpy(), {c: (sub[c].to_numpy(), DECODE_TARGETS[c]) for c in FOOD_FEATURES},
                              sub["episode"].to_numpy(), folds)
            parts.append(s.groupby("group", as_index=False)["skill"].mean().assign(target=name))
        return paired_difference(ctx, pd.concat(parts, ignore_index=True), "near", "far")
    return [ctx.part("agent features best", "Hodges-Lehmann estimate over episodes of held-out skill of the best agent or "
                     "Knollenorgan feature minus the best other sensed variable (wide2; turn, EOD, bite and size "
                     "excluded); Wilcoxon", ranking),
            ctx.part("food near > far", f"Hodges-Lehmann estimate over episodes of held-out skill of food distance and bearing, "
                     f"nearest pellet within {near_cm:g} cm minus beyond; Wilcoxon", food)]


WIDE2_COLLAPSE = analysis_table("dynamics", "wide2", "plsc_collapse")


def _pair_hidden(ctx: Context) -> tuple[pd.DataFrame, pd.DataFrame, list[str]]:
    """Agents 0 and 1 of wide2 at their shared steps (same rows), with their distance ``dist_cm``."""
    j, h = joined(ctx, WIDE2_HIDDEN, WIDE2_STEPS, ["x_cm", "y_cm"])
    keys = ["condition", "episode", "t"]
    a, b = (j[j["agent"] == i].set_index(keys) for i in (0, 1))
    shared = a.index.intersection(b.index)
    if shared.empty:
        raise ValueError("agents 0 and 1 of wide2 share no step with a hidden state")
    a, b = a.loc[shared], b.loc[shared]
    dist = np.hypot(a["x_cm"] - b["x_cm"], a["y_cm"] - b["y_cm"]).rename("dist_cm")
    return a.assign(dist_cm=dist).reset_index(), b.reset_index(), h


@claim("C20", "6G,H", "the PLSC first-component correlation falls with pair distance; significant dimensions "
       "collapse beyond 100 cm", [WIDE2_HIDDEN, WIDE2_STEPS, WIDE2_COLLAPSE])
def c20(ctx: Context) -> list[Part]:
    edges = [-np.inf, *ctx.cfg.analysis.plsc_edges_cm, np.inf]

    def falls() -> Outcome:
        a, b, h = _pair_hidden(ctx)
        rows = []
        for (cond, ep), idx in a.groupby(["condition", "episode"]).indices.items():
            d = a["dist_cm"].to_numpy()[idx]
            for k in range(len(edges) - 1):
                keep = idx[(d > edges[k]) & (d <= edges[k + 1])]
                # shifts=1: only the first component's correlation is used, not the null
                res = plsc(a[h].to_numpy()[keep], b[h].to_numpy()[keep], shifts=1, rng=ctx.rng)
                rows.append({"condition": cond, "episode": ep, "bin": k, "r1": res["correlations"][0]})
        per = per_episode(pd.DataFrame(rows).dropna(), "rho", rho_of("bin", "r1"))
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
WIDE2_DIMS = analysis_table("dynamics", "wide2", "dimensionality")


@claim("C21", "6I,J", "a nearby conspecific lowers wideband power; smaller agents carry more",
       [POWER_NEAR_FAR, WIDE2_DIMS, WIDE2_STEPS])
def c21(ctx: Context) -> list[Part]:
    a = ctx.cfg.analysis

    def near_far() -> Outcome:
        """Per episode, its agents' mean wideband power far minus near (power_near_far), across episodes."""
        wide = ctx.table(POWER_NEAR_FAR).pivot(index=AGENT_EPISODE, columns="where", values="wideband_power")
        wide = wide.reindex(columns=["near", "far"])
        diff = (wide["far"] - wide["near"]).dropna().rename("diff").reset_index()
        return one_sample_part(ctx, per_episode(diff, "diff"), "diff", 0.0, +1)

    def smaller() -> Outcome:
        """Per episode, the smaller agent's wideband power minus the larger's (paired within the episode)."""
        d = smaller_larger(ctx.table(WIDE2_DIMS), ctx.table(WIDE2_STEPS)).dropna(subset=["wideband_power"])
        by_role = d.pivot_table(index=["condition", "episode"], columns="role", values="wideband_power")
        by_role = by_role.reindex(columns=["smaller", "larger"]).dropna()
        diff = (by_role["smaller"] - by_role["larger"]).rename("diff").reset_index()
        return one_sample_part(ctx, diff, "diff", 0.0, +1)
    return [ctx.part("far > near", f"Hodges-Lehmann estimate over episodes of the agents' mean wideband power with "
                     f"the conspecific beyond {a.claims_far_cm:g} cm minus within {a.claims_near_cm:g} cm; Wilcoxon "
                     "signed-rank", near_far),
            ctx.part("smaller carries more", "Hodges-Lehmann estimate over episodes of the wideband power of the "
                     "smaller minus the larger agent (wide2); Wilcoxon signed-rank", smaller)]
