"""The claims of Fig 3 (C4-C9): EOD timing and rates, biting and food against size.

Condition names are those of ``config/assay/<assay>.yaml``.
"""

from __future__ import annotations

import functools

import numpy as np
import pandas as pd
from scipy import stats as sps

from ..analysis.signalling import EVENTS, power_law_vs_exponential_clustered
from ..layout import analysis_table
from .context import Context, claim
from .parts import one_sample_part, per_episode, slope_of, spearman_part, stat_row
from .statistics import rho_of
from .verdicts import Outcome, Part

POWER_LAW, IDIS = analysis_table("signalling", "wide2", "power_law"), analysis_table("signalling", "wide2", "idis")


@claim("C4", "3C,D", "IDIs are heavy-tailed, power-law-like", [POWER_LAW, IDIS])
def c4(ctx: Context) -> list[Part]:
    def compute() -> Outcome:
        row = stat_row(ctx.table(POWER_LAW), source="agents")
        if not bool(row.get("discrete", False)):
            raise ValueError("the power_law table holds a continuous fit: rerun the signalling analysis")
        xmin = float(row["xmin_steps"])
        ids = ctx.table(IDIS)
        ids = ids[ids["condition"] == row["condition"]] if "condition" in ids.columns else ids
        # every IDI's loglikelihood ratio, summed per episode: the episode is the unit (rule 1), not the IDI
        res = power_law_vs_exponential_clustered(ids, xmin)
        if not np.isfinite(res["p"]):
            raise ValueError(res["reason"] or "no clustered test result")
        half = float(sps.t.ppf(1 - ctx.cfg.analysis.claims_alpha / 2, res["df"])) * res["se"]
        mean = float(res["mean_cluster_sum"])
        note = (f"alpha {res['alpha']:.3g}, xmin {xmin:g} steps, R {res['R']:.3g} over {res['n']} IDIs "
                f"(p {res['p_iid']:.3g} if they were independent)")
        return Outcome(mean, float(res["p"]), int(res["n_clusters"]), +1, (mean - half, mean + half),
                       "; ".join(r for r in (note, str(res["reason"] or "")) if r),
                       ci_method="inverts the clustered t-test")
    return [ctx.part("power law", "mean over episodes of the summed loglikelihood ratio of a discrete power law vs "
                     "the exponential (IDIs in steps >= xmin, wide2; powerlaw discrete=True, as the authors); t-test "
                     "across episodes", compute)]


RATE_BY_DISTANCE = analysis_table("signalling", "wide2", "rate_by_distance_episodes")
PERI_EVENT = analysis_table("signalling", "wide2", "peri_event_episodes")


def _friedman_w(rates: np.ndarray) -> tuple[float, float, int, int]:
    """Friedman test of the episodes' mean EOD rates across distance bins, the episode a block (rule 1):
    Kendall's W = chi2 / (n (k - 1)), p, n episodes, k bins; NaN where undefined.

    ``rates``: one row per episode (a bootstrap's episode drawn twice is two rows, two blocks), one column per
    distance bin, NaN where the episode does not reach the bin. Only the bins at least half the episodes reach
    are compared, over the episodes that reach all of them (Friedman needs complete blocks)."""
    wide = rates[:, np.isfinite(rates).mean(axis=0) >= 0.5] if rates.size else rates
    wide = wide[np.isfinite(wide).all(axis=1)]
    n, k = wide.shape
    if k < 3 or n < 2 or np.all(wide == wide[:, :1]):
        return np.nan, np.nan, n, k
    chi2, p = sps.friedmanchisquare(*wide.T)
    return float(chi2 / (n * (k - 1))), float(p), n, k


def _rows(ctx: Context, path: str, column: str, value: str, rate: str) -> pd.DataFrame:
    """The rows of the analysis table ``path`` whose ``column`` is ``value`` and whose ``rate`` is finite; a
    ValueError with the table's reasons when there are none."""
    table = ctx.table(path)
    rows = table[table[column] == value]
    if not rows[rate].notna().any():
        reasons = [r for r in dict.fromkeys(rows["reason"].dropna()) if r]
        raise ValueError("; ".join(reasons) or f"no {column} {value!r} in {path}")
    return rows.dropna(subset=[rate])


@claim("C5", "3E-G", "the EOD rate varies with distance to agent, food and wall", [RATE_BY_DISTANCE])
def c5(ctx: Context) -> list[Part]:
    def compute(to: str) -> Outcome:
        # the signalling analysis's per-episode rates: each agent-episode's mean rate per distance bin (bins with
        # enough steps), averaged over the episode's agents; one row per episode, one column per bin, so that a
        # bootstrap resample only picks rows
        per = _rows(ctx, RATE_BY_DISTANCE, "to", to, "rate_hz")
        wide = per.pivot_table(index=["condition", "episode"], columns="bin", values="rate_hz").reset_index()
        bins = [c for c in wide.columns if c not in ("condition", "episode")]
        w, p, n, k = _friedman_w(wide[bins].to_numpy(np.float64))
        reason = (f"{k} distance bins over {n} episodes that reach them all" if np.isfinite(p) else
                  "fewer than 3 distance bins reached by half the episodes, fewer than 2 such episodes, "
                  "or a constant rate")
        return Outcome(w, p, n, None, ctx.ci(wide, lambda d: _friedman_w(d[bins].to_numpy(np.float64))[0]), reason)
    stat = ("Friedman test of the episodes' mean EOD rate across the distance bins of "
            "docs/methods/analyses.md#analysis-signalling (wide2), the episode a block; effect Kendall's W")
    return [ctx.part(to, stat, functools.partial(compute, to)) for to in ("agent", "food", "wall")]


@claim("C6", "3H-J", "the EOD rate rises around eating, builds before biting, rises around being bitten",
       [PERI_EVENT])
def c6(ctx: Context) -> list[Part]:
    a = ctx.cfg.analysis
    (e0, e1), (b0, b1) = a.claims_event_window, a.claims_baseline_window

    def compute(event: str) -> Outcome:
        # the signalling analysis's per-episode change: the agents' mean rate at the event window's lags minus the
        # baseline window's, averaged over the episode's agents (the agents of one episode are one unit)
        rows = _rows(ctx, PERI_EVENT, "event", event, "change_hz")
        ran = rows[["event_lo", "event_hi", "baseline_lo", "baseline_hi"]].drop_duplicates().to_numpy().tolist()
        if ran != [[e0, e1, b0, b1]]:
            raise ValueError(f"the signalling analysis ran with windows {ran} (event lo, hi, baseline lo, hi), the "
                             f"claims with [{e0}, {e1}] and [{b0}, {b1}]: rerun the analysis")
        return one_sample_part(ctx, per_episode(rows, "change_hz"), "change_hz", 0.0, +1)
    stat = (f"Hodges-Lehmann estimate over episodes of the agents' mean EOD rate at lags [{e0}, {e1}] minus "
            f"[{b0}, {b1}] steps of the event (wide2); Wilcoxon vs 0")
    return [ctx.part(event, stat, functools.partial(compute, event)) for event in EVENTS]


def size_roles(ctx: Context, assay: str, sizes: str) -> Outcome:
    """Per episode, the mean size difference of its events (biter minus bitten, chaser minus chased; the
    interactions analysis's ``sizes`` table), tested across episodes: one episode's many bites are one unit."""
    events = ctx.table(analysis_table("interactions", assay, sizes)).dropna(subset=["size_difference"])
    if events.empty:
        raise ValueError(f"no event with a size difference in {assay}")
    return one_sample_part(ctx, per_episode(events, "size_difference"), "size_difference", 0.0, +1)


@claim("C7", "3K,L; 5M,N", "larger agents bite smaller ones; the win ratio rises with size",
       [analysis_table("interactions", a, "bite_sizes") for a in ("patchy4", "square2")]
       + [analysis_table("behaviour", "patchy4", "win_ratio")])
def c7(ctx: Context) -> list[Part]:
    stat = ("Hodges-Lehmann estimate over episodes of the mean biter minus bitten size of the episode's bites; "
            "Wilcoxon signed-rank")
    parts = [ctx.part(f"biter larger, {assay}", stat, functools.partial(size_roles, ctx, assay, "bite_sizes"))
             for assay in ("patchy4", "square2")]

    def win() -> Outcome:
        ratios = ctx.table(analysis_table("behaviour", "patchy4", "win_ratio"))
        return one_sample_part(ctx, per_episode(ratios, "slope", slope_of("size", "win_ratio")), "slope", 0.0, +1)
    return parts + [ctx.part("win ratio slope, patchy4", "Hodges-Lehmann estimate over episodes of the OLS slope "
                             "of win ratio on size across the episode's agents; Wilcoxon signed-rank", win)]


@claim("C8", "3M,N", "larger agents eat more; Theil T of food tracks size inequality",
       [analysis_table("behaviour", "patchy4", t) for t in ("food_per_agent", "theil")])
def c8(ctx: Context) -> list[Part]:
    def food() -> Outcome:
        per = ctx.table(analysis_table("behaviour", "patchy4", "food_per_agent"))
        return one_sample_part(ctx, per_episode(per, "slope", slope_of("size", "food_eaten")), "slope", 0.0, +1)

    def theil() -> Outcome:
        return spearman_part(ctx, ctx.table(analysis_table("behaviour", "patchy4", "theil")), "size_theil_t",
                             "theil_t", +1)
    return [ctx.part("food ~ size", "Hodges-Lehmann estimate over episodes of the OLS slope of food eaten on size "
                     "across the episode's agents (patchy4); Wilcoxon signed-rank", food),
            ctx.part("Theil ~ size Theil", "Spearman rho of episode Theil T(food) against Theil T(size) (patchy4; "
                     "OLS was decided by one high-leverage episode)", theil)]


@claim("C9", "3O", "size correlates positively with EOD rate",
       [analysis_table("behaviour", "patchy4", "eod_probability")])
def c9(ctx: Context) -> list[Part]:
    def compute() -> Outcome:
        eod = ctx.table(analysis_table("behaviour", "patchy4", "eod_probability"))
        return one_sample_part(ctx, per_episode(eod, "rho", rho_of("size", "eod_probability")), "rho", 0.0, +1)
    return [ctx.part("rho", "Hodges-Lehmann estimate over episodes of the Spearman rho(size, EOD probability) "
                     "across the episode's agents (patchy4); Wilcoxon signed-rank", compute)]
