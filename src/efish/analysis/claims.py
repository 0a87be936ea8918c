"""The paper's claims as verdicts (docs/claims/index.md): one function per claim C1..C21, a registry, the claims table.

Each claim function takes the tables it names (a dict keyed by the path under
``results/{run}/``, e.g. ``analysis/homing/homing/trajectory_shape.parquet``)
and the composed config, and returns one row of :data:`ROW_COLUMNS`: claim,
panel, statistic, effect, 95% bootstrap interval, n, p, verdict, reason. The
verdict rules and the combination of a claim's parts are in
:mod:`efish.analysis.claim_parts`. A statistic an analysis table already holds
(a Dunnett row, a Wilcoxon of sizes, a power-law fit) is read, not recomputed;
the interval resamples episodes of the table it rests on. A table the run lacks
makes that part ``not run`` with a reason naming it, never an exception.

:data:`CLAIMS` names, per claim, the tables it reads; ``efish claims`` and the
``claims`` rule of the workflow read it, and :func:`claims_table` runs all;
:func:`claims_and_parts` also gives one row per part of each claim
(:data:`PART_COLUMNS`) from the same computation.

Condition names are those of ``config/assay/<assay>.yaml``.
"""

from __future__ import annotations

import dataclasses
import functools
from collections.abc import Iterable, Mapping
from pathlib import Path

import numpy as np
import pandas as pd
from scipy import stats as sps

from ..config.recorded import recorded_conditions
from ..config.schema import AssayConfig, EfishConfig
from ..io import read_parquet
from ..layout import analysis_table, assay_table
from . import claims_fig4  # noqa: F401  (registers C10-C13)
from ._tables import AGENT_EPISODE, eod_rate
from .claim_parts import (
    CLAIMS,
    PART_COLUMNS,
    ROW_COLUMNS,
    Context,
    Outcome,
    Part,
    claim,
    from_row,
    heldout_skill,
    joined,
    mann_whitney_part,
    mean_diff,
    median_diff,
    median_minus,
    ols_part,
    one_sample_part,
    paired_difference,
    part_rows,
    present,
    rho_of,
    slope,
    spearman_part,
    stat_row,
    unpaired_equivalence,
)
from .claim_stats import interaction_slope
from .dynamics import DECODE_TARGETS, plsc
from .dynamics_tests import groupsize_parts, smaller_larger
from .homing import error_angles
from .interactions import bite_rate_by_class
from .onepatch import REACH_CONTRASTS, Configs, bot_reach_counts, matched_alone, roles, social_conditions
from .registry import ANALYSES, tables_written
from .signalling import EVENTS, fit_power_law, peri_event_rate
from .stats import spearman

__all__ = ["CLAIMS", "PART_COLUMNS", "ROW_COLUMNS", "claim_tables", "claims_and_parts", "claims_table",
           "produced_tables"]


# --------------------------------------------------------------- Fig 2
HOMING_ELECTRIC, HOMING_RAYCAST = "electric", "raycast"  # config/assay/homing.yaml
TRAJECTORY = analysis_table("homing", "homing", "trajectory_shape")
HOMING_STEPS, HOMING_HIDDEN = assay_table("homing", "steps"), assay_table("homing", "hidden")


def _successful(frame: pd.DataFrame) -> pd.DataFrame:
    """Rows of agent-episodes that ended with their goal reached (every row when there is no success column)."""
    if "success" not in frame.columns:
        return frame
    ok = frame.groupby(AGENT_EPISODE)["success"].transform("any").astype(bool)
    return frame[ok.to_numpy()]


@claim("C1", "2B", "electric homing paths are curvilinear, ray-casting paths straight", [TRAJECTORY])
def c1(ctx: Context) -> list[Part]:
    def compute() -> Outcome:
        shape = ctx.table(TRAJECTORY)
        shape = shape[np.isfinite(shape["tortuosity"])]  # the frozen target never moves: no tortuosity
        if (shape := _successful(shape)).empty:
            raise ValueError("no successful homing episode with a tortuosity")
        return mann_whitney_part(ctx, shape, "tortuosity", "condition", HOMING_ELECTRIC, HOMING_RAYCAST, +1)
    return [ctx.part("tortuosity", "median tortuosity (path / displacement) of successful homing episodes, "
                     "electric minus raycast; Mann-Whitney", compute)]


def _knollen_errors(ctx: Context) -> pd.DataFrame:
    """The homer's Knollenorgan error angles (long table of :func:`error_angles`) in the electric condition."""
    steps = ctx.table(HOMING_STEPS)
    steps = steps[steps["condition"] == HOMING_ELECTRIC]
    err = error_angles(steps) if "err_knollen_rad" in steps.columns else pd.DataFrame()
    err = err[err["channel"] == "knollen"] if len(err) else err
    if err.empty:
        raise ValueError("no finite Knollenorgan error angle in the electric homing steps")
    return err


def _aligned_fraction(err: np.ndarray, a: float) -> float:
    """Fraction of angles within ``a`` of 0 or pi (|cos e| > cos a)."""
    return float(np.mean(np.abs(np.cos(err)) > np.cos(a)))


@claim("C2", "2C", "the error angle is bimodal near parallel and anti-parallel to the target's field",
       [HOMING_STEPS])
def c2(ctx: Context) -> list[Part]:
    a = ctx.cfg.analysis.claims_aligned_rad

    def compute() -> Outcome:
        err = _knollen_errors(ctx)
        steps = ctx.table(HOMING_STEPS)[[*AGENT_EPISODE, "t", "success", "bearing_agent_rad"]]
        err = _successful(err.merge(steps, on=[*AGENT_EPISODE, "t"]))
        if err.empty:
            raise ValueError("no successful electric homing episode")
        # a homer heading straight at the target from the same position: heading + bearing to the target, so
        # its error angle is the observed one plus the bearing (the geometric null of this statistic)
        straight = err["err_rad"] + err["bearing_agent_rad"]
        per = (err.assign(observed=np.abs(np.cos(err["err_rad"])) > np.cos(a),
                          straight=np.abs(np.cos(straight)) > np.cos(a))
               .groupby(["episode", "agent"], as_index=False)[["observed", "straight"]].mean())
        per = per.assign(excess=per["observed"] - per["straight"])
        out = one_sample_part(ctx, per, "excess", 0.0, +1)
        note = (f"median aligned fraction {per['observed'].median():.3f} vs {per['straight'].median():.3f} for a "
                f"straight homer on the same positions, over {len(per)} successful episodes")
        return dataclasses.replace(out, reason="; ".join(r for r in (out.reason, note) if r))
    return [ctx.part("aligned beyond straight homing", f"median over successful episodes of the fraction of steps "
                     f"with |cos(err_knollen)| > cos({a:.3g}) minus that of a homer heading straight at the target "
                     "from the same positions; Wilcoxon vs 0", compute)]


@claim("C3", "2D", "error angles align progressively during successful episodes", [HOMING_STEPS])
def c3(ctx: Context) -> list[Part]:
    def compute() -> Outcome:
        err = _successful(_knollen_errors(ctx).merge(
            ctx.table(HOMING_STEPS)[[*AGENT_EPISODE, "t", "success"]], on=[*AGENT_EPISODE, "t"]))
        if err.empty:
            raise ValueError("no successful electric homing episode")
        err = err.assign(abs_sin=np.abs(np.sin(err["err_rad"])), unit=err["episode"] * 1000 + err["agent"])
        rho = spearman(err, "t_norm", "abs_sin", by="unit")
        rho = rho.assign(episode=rho["group"] // 1000)[np.isfinite(rho["effect"])]
        return one_sample_part(ctx, rho, "effect", 0.0, -1)
    return [ctx.part("alignment", "median over successful episodes of Spearman rho(|sin err_knollen|, normalised "
                     "time); Wilcoxon vs 0", compute)]


# --------------------------------------------------------------- Fig 3
POWER_LAW, IDIS = analysis_table("signalling", "wide2", "power_law"), analysis_table("signalling", "wide2", "idis")


def _r_exponential(idi_steps: np.ndarray, xmin: float) -> float:
    """The discrete power law's normalised loglikelihood ratio against the exponential (the bootstrap's statistic)."""
    fit = fit_power_law(idi_steps, xmin, discrete=True, alternatives=("exponential",))
    return fit["R_exponential"]


@claim("C4", "3C,D", "IDIs are heavy-tailed, power-law-like", [POWER_LAW, IDIS])
def c4(ctx: Context) -> list[Part]:
    def compute() -> Outcome:
        row = stat_row(ctx.table(POWER_LAW), source="agents")
        if not bool(row.get("discrete", False)):
            raise ValueError("the power_law table holds a continuous fit: rerun the signalling analysis")
        xmin = float(row["xmin_steps"])
        ids = ctx.table(IDIS)
        ids = ids[ids["condition"] == row["condition"]] if "condition" in ids.columns else ids
        ci = ctx.ci(ids, lambda d: _r_exponential(d["idi_steps"].to_numpy(np.float64), xmin),
                    units_=("episode", "agent"), resamples=ctx.cfg.analysis.claims_fit_resamples)
        note = f"alpha {float(row['alpha']):.3g}, xmin {xmin:g} steps" if np.isfinite(row["alpha"]) else ""
        why = str(row.get("reason") or "")
        return Outcome(float(row["R_exponential"]), float(row["p_exponential"]), int(row["n"]), +1, ci,
                       "; ".join(r for r in (note, why) if r))
    return [ctx.part("power law", "normalised loglikelihood ratio R of a discrete power law vs the exponential, "
                     "IDIs in steps >= xmin (wide2; powerlaw discrete=True, as the authors); powerlaw's p", compute)]


WIDE2_STEPS, WIDE2_HIDDEN = assay_table("wide2", "steps"), assay_table("wide2", "hidden")
WIDE2_EPISODES = assay_table("wide2", "episodes")


def _kruskal_eta(d: pd.DataFrame) -> tuple[float, float, int]:
    """Kruskal-Wallis of ``rate`` over ``bin``: epsilon^2 = (H - k + 1) / (n - k), p, n; NaN when undefined."""
    samples = [g.to_numpy() for _, g in d.groupby("bin")["rate"]]
    n, k = sum(len(s) for s in samples), len(samples)
    if k < 2 or n <= k or np.ptp(d["rate"]) == 0:
        return np.nan, np.nan, n
    h, p = sps.kruskal(*samples)
    return float((h - k + 1) / (n - k)), float(p), n


@claim("C5", "3E-G", "the EOD rate varies with distance to agent, food and wall", [WIDE2_STEPS])
def c5(ctx: Context) -> list[Part]:
    a = ctx.cfg.analysis

    def compute(to: str) -> Outcome:
        steps = ctx.table(WIDE2_STEPS)
        dist = steps[f"dist_{to}_cm"].to_numpy(np.float64)
        edges = np.linspace(0.0, getattr(a, f"{to}_range_cm"), a.rate_bins + 1)
        frame = steps[AGENT_EPISODE].assign(rate=eod_rate(steps, a.rate_window, ctx.cfg.env.fps),
                                            bin=np.clip(np.searchsorted(edges, dist, side="right") - 1, 0,
                                                        a.rate_bins - 1))
        frame = frame[np.isfinite(frame["rate"]) & (dist >= edges[0]) & (dist <= edges[-1])]
        # one sample per agent-episode and bin (its mean rate): steps of one episode are not independent
        per = frame.groupby([*AGENT_EPISODE, "bin"])["rate"].agg(["mean", "size"])
        per = per[per["size"] >= a.min_samples]["mean"].rename("rate").reset_index()
        if per.empty:
            raise ValueError(f"no agent-episode has {a.min_samples} steps in a {to} distance bin")
        eta, p, n = _kruskal_eta(per)
        reason = "" if np.isfinite(p) else "fewer than 2 distance bins with data, or a constant rate"
        return Outcome(eta, p, n, None, ctx.ci(per, lambda d: _kruskal_eta(d)[0]), reason)
    stat = ("Kruskal-Wallis of the mean EOD rate per agent-episode and distance bin across the bins of "
            "docs/methods/analyses.md#analysis-signalling (wide2); effect epsilon^2")
    return [ctx.part(to, stat, functools.partial(compute, to)) for to in ("agent", "food", "wall")]


@claim("C6", "3H-J", "the EOD rate rises around eating, builds before biting, rises around being bitten",
       [WIDE2_STEPS])
def c6(ctx: Context) -> list[Part]:
    a = ctx.cfg.analysis
    (e0, e1), (b0, b1) = a.claims_event_window, a.claims_baseline_window

    def compute(event: str) -> Outcome:
        if max(abs(e0), abs(e1), abs(b0), abs(b1)) > a.peri_window:
            raise ValueError(f"the windows reach beyond analysis.peri_window = {a.peri_window} steps")
        steps = ctx.table(WIDE2_STEPS)
        # one peri-event curve per agent-episode: peri_event_rate averages within a condition, so each
        # agent-episode becomes its own condition here
        unit = steps["condition"].astype(str) + "|" + steps["episode"].astype(str) + "|" + steps["agent"].astype(str)
        curves = peri_event_rate(steps.assign(condition=unit), event, a.peri_window, a.min_events, a.rate_window,
                                 ctx.cfg.env.fps)
        curves = curves[curves["n_agents"] > 0]
        if curves.empty:
            raise ValueError(f"no agent-episode has {a.min_events} or more '{event}' events")
        lag = curves["lag"]
        near = curves[(lag >= e0) & (lag <= e1)].groupby("condition")["mean_hz"].mean()
        base = curves[(lag >= b0) & (lag <= b1)].groupby("condition")["mean_hz"].mean()
        diff = (near - base).dropna().rename("diff").reset_index()
        # back to the real condition and episode, so the interval resamples episodes within each condition
        # (with the agent-episode as its own stratum, every resample would be the data itself: a zero-width CI)
        parts = diff["condition"].str.rsplit("|", n=2)
        diff["condition"], diff["episode"] = parts.str[0], parts.str[1]
        return one_sample_part(ctx, diff, "diff", 0.0, +1)
    stat = (f"median over agent-episodes of the mean EOD rate at lags [{e0}, {e1}] minus [{b0}, {b1}] steps of "
            "the event (wide2); Wilcoxon vs 0")
    return [ctx.part(event, stat, functools.partial(compute, event)) for event in EVENTS]


def _size_roles(ctx: Context, assay: str, measure: str, sizes: str) -> Outcome:
    """The interactions analysis's Wilcoxon of chaser/biter vs chased/bitten size, interval over its events."""
    row = stat_row(ctx.table(analysis_table("interactions", assay, "size_tests")), measure=measure)
    events = ctx.table(analysis_table("interactions", assay, sizes))
    ci = ctx.ci(events.dropna(subset=["size_difference"]), median_minus("size_difference", 0.0))
    return from_row(row, +1, ci)


@claim("C7", "3K,L; 5M,N", "larger agents bite smaller ones; the win ratio rises with size",
       [analysis_table("interactions", a, t) for a in ("patchy4", "square2") for t in ("size_tests", "bite_sizes")]
       + [analysis_table("behaviour", "patchy4", "win_ratio")])
def c7(ctx: Context) -> list[Part]:
    stat = "median biter minus bitten size over bites; Wilcoxon signed-rank"
    parts = [ctx.part(f"biter larger, {assay}", stat, functools.partial(_size_roles, ctx, assay, "bite",
                                                                         "bite_sizes"))
             for assay in ("patchy4", "square2")]

    def win() -> Outcome:
        return ols_part(ctx, ctx.table(analysis_table("behaviour", "patchy4", "win_ratio")), "size", "win_ratio", +1)
    return parts + [ctx.part("win ratio slope, patchy4", "OLS slope of win ratio on size over agent-episodes", win)]


@claim("C8", "3M,N", "larger agents eat more; Theil T of food tracks size inequality",
       [analysis_table("behaviour", "patchy4", t) for t in ("food_vs_size", "food_per_agent", "theil")])
def c8(ctx: Context) -> list[Part]:
    def food() -> Outcome:
        row = ctx.table(analysis_table("behaviour", "patchy4", "food_vs_size")).iloc[0]
        per = ctx.table(analysis_table("behaviour", "patchy4", "food_per_agent"))
        return from_row(row, +1, ctx.ci(per, lambda d: slope(d["size"], d["food_eaten"])))

    def theil() -> Outcome:
        return spearman_part(ctx, ctx.table(analysis_table("behaviour", "patchy4", "theil")), "size_theil_t",
                             "theil_t", +1)
    return [ctx.part("food ~ size", "OLS slope of food eaten on size over agent-episodes (patchy4)", food),
            ctx.part("Theil ~ size Theil", "Spearman rho of episode Theil T(food) against Theil T(size) (patchy4; "
                     "OLS was decided by one high-leverage episode)", theil)]


@claim("C9", "3O", "size correlates positively with EOD rate",
       [analysis_table("behaviour", "patchy4", t) for t in ("size_tests", "eod_probability")])
def c9(ctx: Context) -> list[Part]:
    def compute() -> Outcome:
        row = stat_row(ctx.table(analysis_table("behaviour", "patchy4", "size_tests")), measure="eod_probability")
        eod = ctx.table(analysis_table("behaviour", "patchy4", "eod_probability"))
        return from_row(row, +1, ctx.ci(eod, rho_of("size", "eod_probability")))
    return [ctx.part("rho", "Spearman rho(size, EOD probability) over agent-episodes (patchy4)", compute)]


# --------------------------------------------------------------- Fig 5
ONEPATCH_FOOD = analysis_table("behaviour", "onepatch", "food_per_agent")
ONEPATCH_CONDITIONS = assay_table("onepatch", "conditions")


def _recorded(ctx: Context, conditions: str) -> Configs:
    """The conditions the assay recorded (who is A, B, the bot or alone, and their sizes)."""
    return recorded_conditions(ctx.table(conditions), conditions)


@claim("C14", "5E-H", "intruder B eats more with A present than alone; A is unaffected; B does better when larger",
       [ONEPATCH_FOOD, ONEPATCH_CONDITIONS])
def c14(ctx: Context) -> list[Part]:
    configs = _recorded(ctx, ONEPATCH_CONDITIONS)
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
        return mann_whitney_part(ctx, b, "food_eaten", "setting", social, "alone", +1)

    def a_unaffected() -> Outcome:
        """A with B (every size class) vs A alone at the same sizes: the two samples have one size mix."""
        controls = [alone for (role, _), alone in matched.items() if role == "A"]
        a = people()
        a = a[(a["role"] == "A") & ((a["setting"] != "alone") | a["condition"].isin(controls))]
        a = a.assign(setting=np.where(a["setting"] == "alone", "alone", "social"))
        return unpaired_equivalence(ctx, a, "food_eaten", "setting", "social", "alone")

    def b_size() -> Outcome:
        b = people().query("role == 'B' and setting != 'alone'")
        return spearman_part(ctx, b, "size", "food_eaten", +1)
    stat = "median food of B with A ({}) minus B alone at B's size; Mann-Whitney"
    return ([ctx.part(f"B social, {c}", stat.format(c), functools.partial(b_social, c))
             for c in social_conditions(configs)]
            + [ctx.part("A social vs alone (equivalent)", "median food of A with B minus A alone at A's sizes "
                        "(size classes pooled, one alone condition per class); Mann-Whitney and TOST", a_unaffected),
               ctx.part("B food vs B size", "Spearman rho of B's food against B's size over the social conditions",
                        b_size)])


BOT_REACH = analysis_table("onepatch", "bot", "reach_rates")
BOT_REACH_TESTS = analysis_table("onepatch", "bot", "reach_tests")
BOT_CONDITIONS = assay_table("bot", "conditions")


def _reach(ctx: Context, contrast: str) -> Outcome:
    """The onepatch analysis's Fisher row of B's reach rate (pooled episodes); interval over episodes."""
    row = stat_row(ctx.table(BOT_REACH_TESTS), contrast=contrast)
    a, b = REACH_CONTRASTS[contrast]
    counts = bot_reach_counts(ctx.table(BOT_REACH), _recorded(ctx, BOT_CONDITIONS), contrast)
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


SQUARE2_STEPS = assay_table("square2", "steps")


def _confronting(ctx: Context) -> Outcome:
    """Per-episode bite rate of confronting pair-steps minus the next-highest class, paired Wilcoxon over episodes."""
    a, steps = ctx.cfg.analysis, ctx.table(SQUARE2_STEPS)
    # bite_rate_by_class sums over a condition; each episode as its own condition gives per-episode rates
    per = bite_rate_by_class(steps.assign(condition=steps["episode"]), a.bout_cm, a.facing_rad, a.away_rad)
    per = per.rename(columns={"condition": "episode"}).dropna(subset=["label", "rate"])
    per = per[per["label"] != "undefined"]
    pooled = per.groupby("label")[["bites", "n_steps"]].sum()
    if "confronting" not in pooled.index or len(pooled) < 2:
        raise ValueError("no confronting pair-step, or no other class, within range")
    other = (pooled["bites"] / pooled["n_steps"]).drop("confronting").idxmax()
    # episodes where both classes occur within range: each episode is one paired unit, never pooled steps
    both = per[per["label"].isin(["confronting", other])]
    both = both[both.groupby("episode")["label"].transform("nunique") == 2]
    out = paired_difference(ctx, both, "confronting", other, value="rate", key="label", unit="episode")
    return dataclasses.replace(out, reason="; ".join(r for r in (out.reason, f"next-highest class: {other}") if r))


@claim("C16", "5K-P", "larger agents chase; biting peaks early in bouts; confronting bouts bite most",
       [analysis_table("interactions", "square2", t) for t in ("size_tests", "chase_sizes", "bite_timing")]
       + [SQUARE2_STEPS])
def c16(ctx: Context) -> list[Part]:
    def timing() -> Outcome:
        bites = ctx.table(analysis_table("interactions", "square2", "bite_timing"))
        return one_sample_part(ctx, bites.dropna(subset=["phase"]), "phase", 0.5, -1)
    return [ctx.part("chaser larger", "median chaser minus chased size over chasing bouts (square2); Wilcoxon",
                     functools.partial(_size_roles, ctx, "square2", "chase", "chase_sizes")),
            ctx.part("bites early", "median normalised bite time in its bout minus 0.5; Wilcoxon", timing),
            ctx.part("confronting bites most", "median over episodes of the bite rate per pair-step within range, "
                     "confronting minus the next-highest class; Wilcoxon signed-rank", functools.partial(_confronting,
                                                                                                       ctx))]


# --------------------------------------------------------------- Fig 6
GROUPSIZE_TESTS = analysis_table("dynamics", "groupsize", "size_tests")


@claim("C17", "6A-C", "hidden dynamics are low-dimensional; D_eff grows with group size only with Knollenorgans",
       [analysis_table("dynamics", a, "dimensionality") for a in ("patchy4", "groupsize")] + [GROUPSIZE_TESTS])
def c17(ctx: Context) -> list[Part]:
    a, width = ctx.cfg.analysis, ctx.cfg.train.hidden

    def low() -> Outcome:
        dims = ctx.table(analysis_table("dynamics", "patchy4", "dimensionality"))
        dims = dims.assign(fraction=dims["d_eff"] / width).dropna(subset=["fraction"])
        return one_sample_part(ctx, dims, "fraction", a.claims_deff_fraction, -1)

    def per_episode() -> pd.DataFrame:
        """D_eff averaged over the agents of each groupsize episode (the episode is the unit)."""
        dims = groupsize_parts(ctx.table(analysis_table("dynamics", "groupsize", "dimensionality")))
        return (dims.groupby(["condition", "episode", "n_agents", "knollenorgans"], as_index=False)["d_eff"].mean()
                .dropna(subset=["d_eff"]))

    def grows() -> Outcome:
        return spearman_part(ctx, per_episode().query("knollenorgans == 'K'"), "n_agents", "d_eff", +1)

    def interaction() -> Outcome:
        d = per_episode()
        on = (d["knollenorgans"] == "K").to_numpy(np.float64)
        b, p, n = interaction_slope(d["n_agents"], d["d_eff"], on)

        def stat(s: pd.DataFrame) -> float:
            try:
                return interaction_slope(s["n_agents"], s["d_eff"], (s["knollenorgans"] == "K").to_numpy(float))[0]
            except ValueError:
                return np.nan
        return Outcome(b, p, n, +1, ctx.ci(d, stat))
    return [ctx.part("low-dimensional", f"median D_eff / width ({width}) minus {a.claims_deff_fraction} (patchy4); "
                     "Wilcoxon", low),
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
    return [ctx.part("err vs bearing", "median over episodes of held-out decoding skill (1 - MSE / MSE of the "
                     "train mean) of err_knollen minus bearing to the target; Wilcoxon", compute)]


#: Fig 6E's sensed variables (decoding rule: never the policy's own outputs or the agent's constant size), and
#: among them the agent and Knollenorgan features the paper finds best.
SENSED = {"dist_agent_cm": False, "knollen_spikes": False, "n_agents_100cm": False, "log_morm_sensed": False,
          "dist_wall_cm": False}
AGENT_FEATURES = ("dist_agent_cm", "knollen_spikes", "n_agents_100cm")
FOOD_FEATURES = ("dist_food_cm", "bearing_food_rad")


@claim("C19", "6E,F", "nearest-agent distance and Knollenorgan features decode best; food variables decode better "
       "when food is in range", [WIDE2_HIDDEN, WIDE2_STEPS])
def c19(ctx: Context) -> list[Part]:
    folds = ctx.cfg.analysis.decode_folds
    near_cm = ctx.cfg.analysis.claims_food_near_cm

    def ranking() -> Outcome:
        missing = [c for c in SENSED if c not in ctx.table(WIDE2_STEPS).columns]
        if missing:
            raise ValueError(f"the wide2 steps table lacks the sensed variables {missing}: rerun the assay")
        j, h = joined(ctx, WIDE2_HIDDEN, WIDE2_STEPS, list(SENSED))
        # a step where no Mormyromast reads above E_min is recorded as NaN; the channel then delivers its floor
        # (every normalised reading 0), so it is decoded as log10 E_min there: every variable on the same steps
        j["log_morm_sensed"] = j["log_morm_sensed"].fillna(np.log10(ctx.cfg.sensors.mormyromast.e_min))
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
    return [ctx.part("agent features best", "median over episodes of held-out skill of the best agent or "
                     "Knollenorgan feature minus the best other sensed variable (wide2; turn, EOD, bite and size "
                     "excluded); Wilcoxon", ranking),
            ctx.part("food near > far", f"median over episodes of held-out skill of food distance and bearing, "
                     f"nearest pellet within {near_cm:g} cm minus beyond; Wilcoxon", food)]


WIDE2_PLSC = analysis_table("dynamics", "wide2", "plsc")


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
       "collapse beyond 100 cm", [WIDE2_HIDDEN, WIDE2_STEPS, WIDE2_PLSC])
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
        return spearman_part(ctx, pd.DataFrame(rows).dropna(), "bin", "r1", -1)

    def collapse() -> Outcome:
        t = ctx.table(WIDE2_PLSC).dropna(subset=["n_significant"])
        near, far = t[t["lo_cm"] == t["lo_cm"].min()], t[np.isinf(t["hi_cm"])]
        if near.empty or far.empty:
            raise ValueError("the PLSC table has no nearest or no farthest distance bin with a result")
        d = float(far["n_significant"].iloc[0] - near["n_significant"].iloc[0])
        verdict = "holds" if d < 0 else "fails" if d > 0 else "weaker"
        return Outcome(d, np.nan, int(near["n_steps"].iloc[0] + far["n_steps"].iloc[0]), -1, verdict=verdict,
                       reason=f"n_significant {int(near['n_significant'].iloc[0])} near, "
                              f"{int(far['n_significant'].iloc[0])} far (a criterion: no p, no interval)")
    return [ctx.part("r1 falls with distance", "Spearman rho of the PLSC first-component correlation per episode "
                     "and distance bin against the bin (wide2)", falls),
            ctx.part("collapse beyond the last edge", "n_significant(farthest bin) minus n_significant(nearest bin), "
                     "pooled PLSC (wide2)", collapse)]


POWER_TESTS, POWER_NEAR_FAR = (analysis_table("dynamics", "wide2", t) for t in ("power_tests", "power_near_far"))
WIDE2_DIMS = analysis_table("dynamics", "wide2", "dimensionality")


@claim("C21", "6I,J", "a nearby conspecific lowers wideband power; smaller agents carry more",
       [POWER_TESTS, POWER_NEAR_FAR, WIDE2_DIMS, WIDE2_STEPS])
def c21(ctx: Context) -> list[Part]:
    a = ctx.cfg.analysis

    def near_far() -> Outcome:
        """The dynamics analysis's Wilcoxon row; interval over agent-episodes of power_near_far."""
        row = stat_row(ctx.table(POWER_TESTS), measure="near_far")
        wide = ctx.table(POWER_NEAR_FAR).pivot(index=AGENT_EPISODE, columns="where", values="wideband_power")
        wide = wide.reindex(columns=["near", "far"])
        diff = (wide["far"] - wide["near"]).dropna().rename("diff").reset_index()
        return from_row(row, +1, ctx.ci(diff, median_minus("diff", 0.0), strata=None))

    def smaller() -> Outcome:
        """The dynamics analysis's Mann-Whitney row; interval over episodes of the dimensionality table."""
        row = stat_row(ctx.table(POWER_TESTS), measure="size")
        d = smaller_larger(ctx.table(WIDE2_DIMS), ctx.table(WIDE2_STEPS)).dropna(subset=["wideband_power"])
        return from_row(row, +1, ctx.ci(d, median_diff("wideband_power", "role", "smaller", "larger"), strata="role"))
    return [ctx.part("far > near", f"median over agent-episodes of wideband power with the conspecific beyond "
                     f"{a.claims_far_cm:g} cm minus within {a.claims_near_cm:g} cm; Wilcoxon (dynamics power_tests)",
                     near_far),
            ctx.part("smaller carries more", "median wideband power of the smaller minus the larger agent per "
                     "episode (wide2); Mann-Whitney (dynamics power_tests)", smaller)]


# ------------------------------------------------------------------ API
def claim_tables() -> list[str]:
    """Every table some claim reads, as paths under ``results/{run}/``, sorted."""
    return sorted({t for c in CLAIMS.values() for t in c.tables})


def produced_tables(assays: Mapping[str, AssayConfig]) -> set[str]:
    """The tables a run of these assays writes (rollout and analysis), as paths under ``results/{run}/``."""
    out = set()
    for name, assay in assays.items():
        written = tables_written(assay)
        out |= {assay_table(name, t) for t in written}
        out |= {analysis_table(a.name, name, t) for a in ANALYSES.values()
                if name in a.assays and set(a.reads) <= set(written) for t in a.outputs}
    return out


def read_claim_tables(results: str | Path, paths: Iterable[str]) -> dict[str, pd.DataFrame]:
    """The tables among ``paths`` that exist under ``results`` (a missing one is simply absent)."""
    results = Path(results)
    return {p: read_parquet(results / p, p) for p in paths if (results / p).is_file()}


def claims_and_parts(results: str | Path, cfg: EfishConfig,
                     claims: Iterable[str] | None = None) -> tuple[pd.DataFrame, pd.DataFrame]:
    """The claims table (one row per claim, :data:`ROW_COLUMNS`) and the parts table (one row per part of each
    claim, :data:`PART_COLUMNS`) of all of CLAIMS, or ``claims``, from the tables under ``results``
    (``results/{run}``): each claim is computed once and both tables come from that computation."""
    chosen = list(CLAIMS) if claims is None else list(claims)
    if unknown := [c for c in chosen if c not in CLAIMS]:
        raise ValueError(f"unknown claims {unknown}: choose among {', '.join(CLAIMS)}")
    tables = read_claim_tables(results, {t for c in chosen for t in CLAIMS[c].tables})
    rows, parts = [], []
    for c in chosen:
        row, found = CLAIMS[c].assess({t: tables[t] for t in CLAIMS[c].tables if t in tables}, cfg)
        rows.append(row)
        parts += part_rows(c, found)
    return (pd.DataFrame(rows, columns=ROW_COLUMNS).astype({"n": "int64"}),
            pd.DataFrame(parts, columns=PART_COLUMNS).astype({"n": "int64", "sign": "float64", "decides": bool}))


def claims_table(results: str | Path, cfg: EfishConfig, claims: Iterable[str] | None = None) -> pd.DataFrame:
    """One row per claim (all of CLAIMS, or ``claims``) from the tables under ``results`` (``results/{run}``)."""
    return claims_and_parts(results, cfg, claims)[0]


# claims_fig4 registered C10-C13 on import, before this module's claims: list them in the paper's order
for _cid, _claim in sorted(CLAIMS.items(), key=lambda item: int(item[0][1:])):
    CLAIMS[_cid] = CLAIMS.pop(_cid)
