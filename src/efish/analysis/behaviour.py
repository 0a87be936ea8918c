"""Foraging and social behaviour (docs/methods/analyses.md#analysis-behaviour; Figs 3, 4, 5): food, inequality,
dominance, bites, spacing, reach.

Inputs are the rollout tables: ``episodes`` (one row per agent-episode) and
``steps`` (one row per agent-step). Tables of statistics use the columns of
:mod:`efish.analysis.stats`.
"""

from __future__ import annotations

import numpy as np
import pandas as pd
from scipy import stats as sps

from ._tables import AGENT_EPISODE, EPISODE, PerCondition, agent_sizes, nan_frame, or_nan_row, require, values_of
from .inequality import theil_t, win_ratio
from .selection import ols_fit
from .stats import STAT_COLUMNS, stars


def food_per_agent_episode(episodes: pd.DataFrame) -> pd.DataFrame:
    """Food eaten per agent-episode with the agent's share of its episode's food and its size rank.

    ``size_rank`` is 0 for the smallest agent of the episode (ties broken by
    agent id); ``food_share`` is NaN with a reason when the episode's agents ate nothing.
    """
    require(episodes, [*AGENT_EPISODE, "size", "food_eaten"], "episodes table")
    out = episodes[[*AGENT_EPISODE, "size", "food_eaten"]].sort_values(AGENT_EPISODE).reset_index(drop=True)
    by_episode = out.groupby(EPISODE, sort=False)
    out["size_rank"] = (by_episode["size"].rank(method="first") - 1).astype("Int64")  # <NA> for a missing size
    total = by_episode["food_eaten"].transform("sum").to_numpy(np.float64)
    out["food_share"] = np.divide(out["food_eaten"], total, out=np.full(len(out), np.nan), where=total > 0)
    out["reason"] = np.select([out["food_eaten"].isna(), total <= 0],
                              ["food_eaten is missing", "no food eaten in the episode"], "")
    return out


def food_vs_size(episodes: pd.DataFrame) -> pd.DataFrame:
    """OLS of food_eaten on size over all agent-episodes of each condition (scipy.stats.linregress), Fig 3M.

    Stat rows: effect = slope (food per unit size), statistic = t of the slope,
    p of the slope; plus ``intercept`` and ``r2``.
    """
    require(episodes, ["condition", "size", "food_eaten"], "episodes table")
    rows = []
    for cond, sub in list(episodes.groupby("condition", sort=True)) or [(np.nan, episodes)]:
        xy = sub[["size", "food_eaten"]].astype(np.float64).dropna().to_numpy()
        reason = "fewer than 3 agent-episodes" if len(xy) < 3 else ""
        reason = reason or ("size is constant" if np.ptp(xy[:, 0]) == 0 else "")
        reason = reason or ("food is constant" if np.ptp(xy[:, 1]) == 0 else "")
        row = {"test": "ols", "group": cond, "control": "size", "n": len(xy), "n_control": len(xy),
               "effect_kind": "slope", "reason": reason}
        if reason:
            rows.append({**row, "effect": np.nan, "statistic": np.nan, "p": np.nan, "intercept": np.nan,
                         "r2": np.nan})
            continue
        fit = sps.linregress(xy[:, 0], xy[:, 1])
        t = fit.slope / fit.stderr if fit.stderr > 0 else np.inf  # a perfect line: infinite t, p = 0
        rows.append({**row, "effect": fit.slope, "statistic": t, "p": fit.pvalue, "intercept": fit.intercept,
                     "r2": fit.rvalue ** 2})
    out = pd.DataFrame(rows, columns=[*STAT_COLUMNS, "intercept", "r2"])
    out["stars"] = [stars(p) for p in out["p"]]
    return out


def food_vs_size_per_episode(episodes: pd.DataFrame) -> pd.DataFrame:
    """Slope, intercept and R^2 of food_eaten ~ size over each episode's agents (the seed-selection fit,
    docs/methods/training.md#seed-selection)."""
    require(episodes, [*EPISODE, "size", "food_eaten"], "episodes table")
    rows = []
    for (cond, ep), sub in episodes.groupby(EPISODE, sort=True):
        if sub[["size", "food_eaten"]].isna().any(axis=None):
            slope, intercept, r2, reason = np.nan, np.nan, np.nan, "missing size or food_eaten"
        else:
            slope, intercept, r2 = ols_fit(sub["size"], sub["food_eaten"])
            reason = "size is constant in the episode" if np.isnan(slope) else ""
        rows.append({"condition": cond, "episode": ep, "n": len(sub), "slope": slope, "intercept": intercept,
                     "r2": r2, "reason": reason})
    return pd.DataFrame(rows, columns=["condition", "episode", "n", "slope", "intercept", "r2", "reason"])


def theil_per_episode(episodes: pd.DataFrame, value: str = "food_eaten") -> pd.DataFrame:
    """Theil T of ``value`` over all agents of each episode (0 ln 0 = 0), and Theil T of their sizes (Fig 3N).

    An episode in which nobody ate has T = 0 (nothing is unequally shared); an
    episode with a missing or negative value is NaN with a reason.
    """
    require(episodes, [*EPISODE, "size", value], "episodes table")
    rows = []
    for (cond, ep), sub in episodes.groupby(EPISODE, sort=True):
        v, s = sub[value].to_numpy(np.float64), sub["size"].to_numpy(np.float64)
        bad = not (np.all(np.isfinite(v)) and np.all(v >= 0))
        rows.append({"condition": cond, "episode": ep, "n_agents": len(sub), "total": v.sum(),
                     "theil_t": np.nan if bad else theil_t(v),
                     "size_theil_t": theil_t(s) if np.all(np.isfinite(s) & (s >= 0)) else np.nan,
                     "reason": f"{value} has missing or negative values" if bad else ""})
    return pd.DataFrame(rows, columns=["condition", "episode", "n_agents", "total", "theil_t", "size_theil_t",
                                       "reason"])


def win_ratios(episodes: pd.DataFrame) -> pd.DataFrame:
    """Win ratio given / (given + received) per agent-episode with its size (Fig 3L); NaN with a reason if no bites."""
    require(episodes, [*AGENT_EPISODE, "size", "bites_given", "bites_received"], "episodes table")
    out = episodes[[*AGENT_EPISODE, "size", "bites_given", "bites_received"]].reset_index(drop=True)
    out["win_ratio"] = win_ratio(out["bites_given"], out["bites_received"])
    out["reason"] = np.where(out["win_ratio"].isna(), "no bites given or received", "")
    return out


def _size_classes(steps: pd.DataFrame, by: str, bins: int) -> pd.Series:
    """Size class per (condition, episode, agent): rank within the episode (0 smallest) or an equal bin of [0, 1]."""
    sizes = agent_sizes(steps)
    if by == "rank":
        return sizes.groupby(level=EPISODE, sort=False).rank(method="first") - 1  # NaN for a missing size
    if by == "bin":
        return pd.Series(np.clip(np.floor(sizes.to_numpy() * bins), 0, bins - 1), index=sizes.index)
    raise ValueError(f"by must be 'rank' or 'bin', got {by!r}")


def bite_matrix(steps: pd.DataFrame, by: str = "rank", bins: int = 4) -> pd.DataFrame:
    """Bites from each biter size class to each victim size class, per condition (Fig 3K).

    A bite is a step whose ``bite_target`` names a victim (>= 0). Classes are
    size ranks within the episode (``by="rank"``) or ``bins`` equal size bins
    (``by="bin"``). Every (biter, victim) class pair is listed, zeros included;
    ``fraction`` of the condition's bites is NaN with a reason when there were none.
    """
    require(steps, [*AGENT_EPISODE, "t", "size", "bite_target"], "steps table")
    classes = _size_classes(steps, by, bins)
    if classes.isna().all():
        return nan_frame("no agent has a known size", condition=np.nan, biter_class=np.nan, victim_class=np.nan,
                         bites=0)
    n_classes = bins if by == "bin" else int(classes.max()) + 1
    bites = steps.loc[steps["bite_target"].to_numpy() >= 0, [*AGENT_EPISODE, "bite_target"]]
    biter = classes.reindex(pd.MultiIndex.from_frame(bites[AGENT_EPISODE])).to_numpy()
    victim = classes.reindex(pd.MultiIndex.from_arrays([bites["condition"], bites["episode"],
                                                        bites["bite_target"]])).to_numpy()
    known = np.isfinite(biter) & np.isfinite(victim)  # a missing size, or a target that is no agent, has no class
    parts = []
    for cond in sorted(steps["condition"].unique()):
        mine = (bites["condition"] == cond).to_numpy() & known
        grid, _, _ = np.histogram2d(biter[mine], victim[mine], bins=n_classes, range=[[0, n_classes]] * 2)
        total = grid.sum()
        b, v = np.meshgrid(np.arange(n_classes), np.arange(n_classes), indexing="ij")
        lost = int(np.sum((bites["condition"] == cond).to_numpy() & ~known))
        reason = "" if total else "no bite has a known size class" if lost else "no bites"
        parts.append(pd.DataFrame({
            "condition": cond, "biter_class": b.ravel(), "victim_class": v.ravel(), "bites": grid.ravel().astype(int),
            "fraction": grid.ravel() / total if total else np.nan,
            "per_episode": grid.ravel() / steps.loc[steps["condition"] == cond, "episode"].nunique(),
            "unclassified_bites": lost, "reason": reason}))
    return pd.concat(parts, ignore_index=True).assign(classes_by=by)


def _per_agent_episode(steps: pd.DataFrame, column: str, reason_if_nan: str) -> pd.DataFrame:
    """Mean and median of a steps column per agent-episode, with the agent's size; NaN rows say why."""
    require(steps, [*AGENT_EPISODE, "size", column], "steps table")
    g = steps.groupby(AGENT_EPISODE, sort=True)
    out = g.agg(size=("size", "first"), n_steps=(column, "size"), mean=(column, "mean"),
                median=(column, "median")).reset_index()
    out["reason"] = np.where(out["mean"].isna(), reason_if_nan, "")
    return out


def nearest_neighbour(steps: pd.DataFrame) -> pd.DataFrame:
    """Mean and median nearest-neighbour distance (cm) per agent-episode (Fig 4D); NaN for a lone agent."""
    out = _per_agent_episode(steps, "dist_agent_cm", "no other agent")
    return out.rename(columns={"mean": "mean_nn_dist_cm", "median": "median_nn_dist_cm"})


def eod_probability(steps: pd.DataFrame) -> pd.DataFrame:
    """Fraction of steps with an EOD per agent-episode, with the agent's size (Figs 3O, 4C)."""
    frame = steps.assign(eod=steps["eod"].astype(np.float64)) if "eod" in steps else steps
    out = _per_agent_episode(frame, "eod", "no steps")
    return out.drop(columns="median").rename(columns={"mean": "eod_probability"})


def episode_summary(episodes: pd.DataFrame, food: pd.DataFrame | None = None) -> pd.DataFrame:
    """One row per episode: total food, food per agent, Theil T, mean EOD probability, spacing and bites (Fig 4);
    with the ``food`` table (one row per pellet that existed, regrown ones included) also ``food_offered``, the
    pellets the episode had (0 where the food table has none), so a reader can tell a ceiling (every pellet
    eaten) from the summary alone."""
    cols = ["eod_probability", "mean_nn_dist_cm", "bites_given"]
    require(episodes, [*EPISODE, "food_eaten", *cols], "episodes table")
    g = episodes.groupby(EPISODE, sort=True)
    out = g.agg(n_agents=("food_eaten", "size"), food_total=("food_eaten", "sum"),
                food_per_agent=("food_eaten", "mean"), eod_probability=("eod_probability", "mean"),
                mean_nn_dist_cm=("mean_nn_dist_cm", "mean"), bites=("bites_given", "sum")).reset_index()
    if food is not None:
        offered = food.groupby(EPISODE).size()
        out["food_offered"] = out.set_index(EPISODE).index.map(offered).fillna(0).astype(np.int64)
    theil = theil_per_episode(episodes)
    # both are sorted by (condition, episode) with one row per episode, so they align row by row
    return out.assign(theil_t=theil["theil_t"].to_numpy(), reason=theil["reason"].to_numpy())


def food_time_course(steps: pd.DataFrame, every: int = 1) -> pd.DataFrame:
    """Mean +- SEM cumulative food eaten by each agent over time, across episodes (one-patch, Fig 5G,H).

    One row per (condition, agent, t) for t a multiple of ``every``; ``n_episodes``
    counts the episodes with a row at t (episodes that ended earlier drop out).
    """
    require(steps, [*AGENT_EPISODE, "t", "ate"], "steps table")
    frame = steps[[*AGENT_EPISODE, "t", "ate"]].sort_values([*AGENT_EPISODE, "t"])
    frame["food"] = frame["ate"].astype(np.int64).groupby([frame[k] for k in AGENT_EPISODE], sort=False).cumsum()
    frame = frame[frame["t"] % every == 0]
    out = frame.groupby(["condition", "agent", "t"], sort=True)["food"].agg(["size", "mean", "sem"]).reset_index()
    out = out.rename(columns={"size": "n_episodes", "mean": "mean_food", "sem": "sem_food"})
    return or_nan_row(out.assign(reason=""), "empty steps table")


def reach_times(steps: pd.DataFrame, patch_xy_cm: tuple[PerCondition, PerCondition],
                reach_cm: PerCondition) -> pd.DataFrame:
    """First step at which each agent's centre is within ``reach_cm`` of the patch centre, per agent-episode.

    The patch is the run's (the centre of its arena and ``arena.onepatch_radius_cm``,
    docs/model/environment.md#arenas-and-food), passed in by the caller rather
    than defaulted here, where a second copy of the arena could disagree with
    the run: numbers, or each condition's as it recorded them (:data:`~efish.analysis._tables.PerCondition`).
    ``reached`` is False and ``t_reach`` NaN for an agent that never got there.
    """
    require(steps, [*AGENT_EPISODE, "t", "x_cm", "y_cm"], "steps table")
    x, y, r = (values_of(v, steps["condition"]) for v in (*patch_xy_cm, reach_cm))
    d = np.hypot(steps["x_cm"].to_numpy(np.float64) - x, steps["y_cm"].to_numpy(np.float64) - y)
    frame = steps[[*AGENT_EPISODE, "t"]].assign(t_in=np.where(d <= r, steps["t"], np.nan))
    out = frame.groupby(AGENT_EPISODE, sort=True)["t_in"].min().rename("t_reach").reset_index()
    out["reached"] = out["t_reach"].notna()
    return out


def reach_rates(steps: pd.DataFrame, patch_xy_cm: tuple[PerCondition, PerCondition], reach_cm: PerCondition,
                agent: int | None = None) -> pd.DataFrame:
    """Fraction of episodes in which an agent reached the patch, and its median time to it, per condition and agent.

    ``agent`` keeps one agent only, e.g. the trained agent B of the bot assay
    (:func:`bot_reach_rates`).
    """
    times = reach_times(steps, patch_xy_cm, reach_cm)
    if agent is not None:
        times = times[times["agent"] == agent]
    if times.empty:
        return nan_frame("no agent-episodes", condition=np.nan, agent=agent, n_episodes=0, n_reached=0,
                         reach_rate=np.nan, median_t_reach=np.nan)
    g = times.groupby(["condition", "agent"], sort=True)
    out = g.agg(n_episodes=("reached", "size"), n_reached=("reached", "sum"),
                median_t_reach=("t_reach", "median")).reset_index()
    out["reach_rate"] = out["n_reached"] / out["n_episodes"]
    out["reason"] = np.where(out["n_reached"] == 0, "no episode reached the patch (median time undefined)", "")
    return out


def bot_reach_rates(steps: pd.DataFrame, patch_xy_cm: tuple[float, float], reach_cm: float,
                    agent: int = 1) -> pd.DataFrame:
    """Reach rate of the trained agent (``agent``, B) per bot condition (Fig 5I,J; the bot is agent 0,
    docs/methods/assays.md#assay-bot)."""
    return reach_rates(steps, patch_xy_cm, reach_cm, agent=agent)
