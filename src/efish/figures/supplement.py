"""Supplementary panels: training curves and the seed-selection landscape (SPEC 10, 13)."""

from __future__ import annotations

import numpy as np
import pandas as pd

from .panel import Panel
from .style import NEUTRAL_COLOUR, SELECTED_COLOUR, missing


def training_curves(tables: dict[str, pd.DataFrame], ax) -> None:
    """Mean episode return against env steps, one line per seed; the selected seed is drawn on top in colour."""
    metrics = tables["metrics"].dropna(subset=["episode_return"])
    if metrics.empty:
        missing(ax, "no episode finished during training")
        return
    selected = _selected_seed(tables)
    for seed, m in metrics.groupby("seed"):
        chosen = seed == selected
        ax.plot(m["env_steps"], m["episode_return"], color=SELECTED_COLOUR if chosen else NEUTRAL_COLOUR,
                alpha=1.0 if chosen else 0.6, zorder=3 if chosen else 2, label=f"seed {seed}" if chosen else None)
    ax.set_xlabel("env steps")
    ax.set_ylabel("episode return")
    ax.set_title("Training curves")
    if selected is not None:
        ax.legend(loc="lower right")


def seed_landscape(tables: dict[str, pd.DataFrame], ax) -> None:
    """Each seed's food per episode against its size-food slope; marker area ~ R^2, the selected seed ringed."""
    ranking = tables["ranking"]
    area = 20 + 200 * ranking["r2"].fillna(0).clip(0, 1)
    colours = np.where(ranking["eligible"], NEUTRAL_COLOUR, "white")
    ax.scatter(ranking["slope"], ranking["food_per_episode"], s=area, c=colours, edgecolors=NEUTRAL_COLOUR)
    chosen = ranking[ranking["selected"]]
    ax.scatter(chosen["slope"], chosen["food_per_episode"], s=area[chosen.index] + 60, facecolors="none",
               edgecolors=SELECTED_COLOUR, linewidths=1.5)
    for _, row in ranking.iterrows():
        ax.annotate(str(int(row["seed"])), (row["slope"], row["food_per_episode"]), fontsize=6,
                    xytext=(3, 3), textcoords="offset points")
    ax.axvline(0, color=NEUTRAL_COLOUR, lw=0.5, ls=":")
    ax.set_xlabel("median slope of food ~ size")
    ax.set_ylabel("food per episode")
    note = " (fallback: no seed had a positive intercept)" if ranking["fallback"].any() else ""
    ax.set_title("Seed landscape" + note)


def _selected_seed(tables: dict[str, pd.DataFrame]) -> int | None:
    ranking = tables.get("ranking")
    if ranking is None or not ranking["selected"].any():
        return None
    return int(ranking.loc[ranking["selected"], "seed"].iloc[0])


PANELS = [
    Panel("supp", "training_curves", training_curves,
          {"metrics": "train/seed_{seed}/metrics.parquet", "ranking": "analysis/selection/ranking.parquet"},
          "Mean episode return during training, every seed; the selected seed in colour."),
    Panel("supp", "seed_landscape", seed_landscape, {"ranking": "analysis/selection/ranking.parquet"},
          "Seed selection (SPEC 10): food per episode against the size-food slope; marker area is R^2, "
          "hollow markers are seeds dropped for a non-positive intercept, the ring marks the selected seed."),
]
