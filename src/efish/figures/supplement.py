"""Supplementary panels: training, seed selection and the top-ranked seeds (docs/methods/training.md#seed-selection,
docs/methods/figures.md#panels).

Training panels read every seed's ``metrics.parquet`` (one row per PPO
update); the selected seed is drawn in colour on top of the others in grey.
Curves are smoothed with a 5-point exponential moving average (span 5, as in
the paper's supplement); the raw values are drawn faintly beneath.
"""

from __future__ import annotations

import numpy as np
import pandas as pd

from .. import layout
from ..analysis.selection import ols_fit
from .panel import Panel
from .style import AGENT_COLOURS, NEUTRAL_COLOUR, SELECTED_COLOUR, missing

EMA_SPAN = 5
#: (metrics column, label) of the reward components drawn across seeds
REWARD_PARTS = (("reward_food", "food"), ("reward_bitten", "bitten"))


def ema(values: pd.Series, span: int = EMA_SPAN) -> pd.Series:
    """Exponential moving average with ``span`` (alpha = 2 / (span + 1)), ignoring NaN updates.

    >>> ema(pd.Series([0.0, 3.0]), span=2).round(3).tolist()
    [0.0, 2.25]
    """
    return values.ewm(span=span, ignore_na=True).mean()


def _selected_seed(tables: dict[str, pd.DataFrame]) -> int | None:
    ranking = tables.get("ranking")
    if ranking is None or not ranking["selected"].any():
        return None
    return int(ranking.loc[ranking["selected"], "seed"].iloc[0])


def _per_seed(ax, tables: dict[str, pd.DataFrame], column: str, colour: str | None = None,
              label: str | None = None) -> bool:
    """One EMA-smoothed line of ``column`` against env steps per seed; False when no seed has a value."""
    metrics = tables["metrics"]
    if column not in metrics or not metrics[column].notna().any():
        return False
    selected = _selected_seed(tables)
    others_labelled = False
    for seed, m in metrics.groupby("seed"):
        m = m.dropna(subset=[column])
        chosen = seed == selected
        line_colour = colour or (SELECTED_COLOUR if chosen else NEUTRAL_COLOUR)
        if chosen:
            line_label = label or f"seed {seed} (selected)"
        elif not others_labelled and (colour is None or selected is None):
            line_label = label or ("other seeds" if selected is not None else "every seed")
            others_labelled = True  # one legend entry for all the grey lines
        else:
            line_label = None
        ax.plot(m["env_steps"], m[column], color=line_colour, alpha=0.15, lw=0.6)
        ax.plot(m["env_steps"], ema(m[column]), color=line_colour, alpha=1.0 if chosen else 0.6,
                lw=1.2 if chosen else 0.8, zorder=3 if chosen else 2, ls="-" if chosen or not colour else "--",
                label=line_label)
    ax.set_xlabel("env steps")
    return True


def training_curves(tables: dict[str, pd.DataFrame], ax) -> None:
    """Mean episode return against env steps, every seed (5-point EMA), the selected seed in colour."""
    if not _per_seed(ax, tables, "episode_return"):
        missing(ax, "no episode finished during training")
        return
    ax.set_ylabel("episode return")
    ax.set_title("Training return")
    if _selected_seed(tables) is not None:
        ax.legend(loc="lower right")


def losses(tables: dict[str, pd.DataFrame], ax) -> None:
    """Policy (clipped surrogate) and value (Huber) losses per update, every seed, 5-point EMA; value on a log
    axis on the right, since it falls by orders of magnitude while the policy loss stays near zero."""
    metrics = tables["metrics"]
    if not {"policy_loss", "value_loss"} <= set(metrics.columns):
        missing(ax, "the metrics tables have no loss columns")
        return
    _per_seed(ax, tables, "policy_loss", colour=AGENT_COLOURS[0], label="policy")
    ax.set_ylabel("policy loss", color=AGENT_COLOURS[0])
    right = ax.twinx()
    _per_seed(right, tables, "value_loss", colour=AGENT_COLOURS[1], label="value")
    if (metrics["value_loss"] > 0).all():
        right.set_yscale("log")
    right.set_ylabel("value loss", color=AGENT_COLOURS[1])
    right.spines["right"].set_visible(True)
    ax.set_title("PPO losses")


def entropy(tables: dict[str, pd.DataFrame], ax) -> None:
    """Policy entropy per update (nats, summed over the action heads), every seed, 5-point EMA."""
    if not _per_seed(ax, tables, "entropy"):
        missing(ax, "the metrics tables have no entropy column")
        return
    ax.set_ylabel("policy entropy (nats)")
    ax.set_title("Policy entropy")


def reward_components(tables: dict[str, pd.DataFrame], ax) -> None:
    """The food and bitten reward components (mean per agent-step) against env steps, every seed, 5-point EMA."""
    drawn = [_per_seed(ax, tables, column, colour=colour, label=label)
             for (column, label), colour in zip(REWARD_PARTS, AGENT_COLOURS[2:], strict=False)]
    if not any(drawn):
        missing(ax, "the metrics tables have no reward_food / reward_bitten columns")
        return
    ax.axhline(0, color=NEUTRAL_COLOUR, lw=0.5, ls=":")
    ax.set_ylabel("reward per agent-step")
    ax.set_title("Reward components")
    ax.legend(loc="best")


def seed_landscape(tables: dict[str, pd.DataFrame], ax) -> None:
    """Each seed's food per episode (x) against its median size-food slope (y), R^2 as colour; hollow markers
    are seeds dropped for a non-positive intercept, the ring marks the selected seed
    (docs/methods/training.md#seed-selection)."""
    import matplotlib.pyplot as plt

    ranking = tables["ranking"]
    if ranking.empty:
        missing(ax, "the seed ranking is empty")
        return
    r2 = ranking["r2"].fillna(0).clip(0, 1)
    eligible, dropped = ranking[ranking["eligible"]], ranking[~ranking["eligible"]]
    points = ax.scatter(eligible["food_per_episode"], eligible["slope"], c=r2[eligible.index], cmap="viridis",
                        vmin=0, vmax=1, s=28, edgecolors="black", linewidths=0.4, zorder=3)
    ax.scatter(dropped["food_per_episode"], dropped["slope"], s=28, facecolors="none", edgecolors=NEUTRAL_COLOUR,
               zorder=2, label="dropped (intercept <= 0)" if len(dropped) else None)
    chosen = ranking[ranking["selected"]]
    ax.scatter(chosen["food_per_episode"], chosen["slope"], s=110, facecolors="none", edgecolors=SELECTED_COLOUR,
               linewidths=1.5, zorder=4, label="selected")
    for _, row in ranking.iterrows():
        ax.annotate(str(int(row["seed"])), (row["food_per_episode"], row["slope"]), fontsize=6,
                    xytext=(3, 3), textcoords="offset points")
    ax.axhline(0, color=NEUTRAL_COLOUR, lw=0.5, ls=":")
    plt.colorbar(points, ax=ax, label="R$^2$ (food ~ size)", shrink=0.8)
    ax.set_xlabel("food per episode")
    ax.set_ylabel("median slope of food ~ size")
    note = " (fallback)" if ranking["fallback"].any() else ""
    ax.set_title("Seed landscape" + note)
    ax.legend(loc="best", fontsize=6)


def _top_seed_lines(ax, episodes: pd.DataFrame, y: str) -> bool:
    """Per top seed (in rank order, agent colours by rank): ``y`` against size with its OLS line."""
    if episodes.empty or y not in episodes:
        return False
    for rank, sub in episodes.groupby("rank", sort=True):
        colour = AGENT_COLOURS[(int(rank) - 1) % len(AGENT_COLOURS)]
        sub = sub.dropna(subset=["size", y])
        ax.scatter(sub["size"], sub[y], s=6, color=colour, alpha=0.5, edgecolors="none")
        slope, intercept, _ = ols_fit(sub["size"], sub[y])
        if np.isfinite(slope):
            xs = np.array([sub["size"].min(), sub["size"].max()])
            ax.plot(xs, intercept + slope * xs, color=colour, label=f"#{rank}: seed {int(sub['seed'].iloc[0])}")
    ax.set_xlabel("body size")
    ax.legend(loc="best", fontsize=6)
    return True


def top_seeds_food(tables: dict[str, pd.DataFrame], ax) -> None:
    """Food eaten per agent-episode against size in the patchy 4-agent arena, per top-ranked seed."""
    if not _top_seed_lines(ax, tables["episodes"], "food_eaten"):
        missing(ax, "no top-seed patchy4 episodes")
        return
    ax.set_ylabel("food eaten per episode")
    ax.set_title("Top seeds: food vs size")


def top_seeds_eod(tables: dict[str, pd.DataFrame], ax) -> None:
    """EOD probability per agent-episode against size in the wide 2-agent arena, per top-ranked seed."""
    if not _top_seed_lines(ax, tables["episodes"], "eod_probability"):
        missing(ax, "no top-seed wide2 episodes")
        return
    ax.set_ylabel("EOD probability per step")
    ax.set_title("Top seeds: EOD vs size")


def top_seeds_bites(tables: dict[str, pd.DataFrame], ax) -> None:
    """Bites given minus bites received per agent-episode against size in the square 2-agent arena, per
    top-ranked seed (positive: the agent bit more than it was bitten)."""
    episodes = tables["episodes"]
    if not {"bites_given", "bites_received"} <= set(episodes.columns):
        missing(ax, "no top-seed square2 episodes")
        return
    net = episodes.assign(net_bites=episodes["bites_given"] - episodes["bites_received"])
    if not _top_seed_lines(ax, net, "net_bites"):
        missing(ax, "no top-seed square2 episodes")
        return
    ax.axhline(0, color=NEUTRAL_COLOUR, lw=0.5, ls=":")
    ax.set_ylabel("bites given - received")
    ax.set_title("Top seeds: biting vs size")


#: ``{seed}`` stands for every trained seed (:func:`efish.figures.render.input_paths` expands it).
METRICS = {"metrics": layout.training_file(layout.seed_name("{seed}"), "metrics.parquet"), "ranking": layout.RANKING}

PANELS = [
    Panel("supp", "training_curves", training_curves, METRICS,
          "Mean return of the training episodes that ended in each PPO update against env steps, every seed "
          "(5-point EMA over the raw values, faint); the selected seed in colour (train metrics tables)."),
    Panel("supp", "losses", losses, METRICS,
          "PPO policy loss (left axis) and value loss (right, log) per update, every seed, 5-point EMA "
          "(train metrics tables)."),
    Panel("supp", "entropy", entropy, METRICS,
          "Policy entropy per update, every seed, 5-point EMA; the selected seed in colour (train metrics tables)."),
    Panel("supp", "reward_components", reward_components, METRICS,
          "Food reward and bitten penalty, mean per agent-step of each rollout, every seed, 5-point EMA "
          "(train metrics tables)."),
    Panel("supp", "seed_landscape", seed_landscape, {"ranking": layout.RANKING},
          "Seed selection (docs/methods/training.md#seed-selection): food per episode against the median size-food "
          "slope of each seed's selection episodes, R^2 as colour; hollow markers are seeds dropped for a "
          "non-positive intercept, the ring marks the selected seed (analysis/selection/ranking table)."),
    Panel("supp", "top_seeds_food", top_seeds_food, {"episodes": layout.stacked_seeds_table("patchy4")},
          "The top-ranked seeds in the patchy 4-agent assay: food per agent-episode against size with each "
          "seed's OLS line (seeds/patchy4 episodes table, stacked over the top seeds)."),
    Panel("supp", "top_seeds_eod", top_seeds_eod, {"episodes": layout.stacked_seeds_table("wide2")},
          "The top-ranked seeds in the wide 2-agent assay: EOD probability per agent-episode against size with "
          "each seed's OLS line (seeds/wide2 episodes table)."),
    Panel("supp", "top_seeds_bites", top_seeds_bites, {"episodes": layout.stacked_seeds_table("square2")},
          "The top-ranked seeds in the square 2-agent assay: bites given minus received per agent-episode "
          "against size with each seed's OLS line (seeds/square2 episodes table)."),
]
