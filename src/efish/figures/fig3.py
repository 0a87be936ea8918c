"""Fig 3: foraging behaviour of the selected seed in the 4-agent patchy arena (SPEC 13)."""

from __future__ import annotations

import numpy as np
import pandas as pd

from ..analysis.selection import ols_fit
from .panel import Panel
from .style import NEUTRAL_COLOUR, SELECTED_COLOUR, missing


def food_vs_size(tables: dict[str, pd.DataFrame], ax) -> None:
    """Panel M: food eaten per agent-episode against body size, with the pooled OLS line and its R^2."""
    episodes = tables["episodes"]
    if episodes.empty:
        missing(ax, "patchy4 episodes table is empty")
        return
    size, food = episodes["size"].to_numpy(float), episodes["food_eaten"].to_numpy(float)
    ax.scatter(size, food, s=10, color=NEUTRAL_COLOUR, alpha=0.7, edgecolors="none")
    slope, intercept, r2 = ols_fit(size, food)
    if np.isfinite(slope):
        xs = np.array([size.min(), size.max()])
        ax.plot(xs, intercept + slope * xs, color=SELECTED_COLOUR,
                label=f"slope {slope:.2g}, R$^2$ {r2:.2f}")
        ax.legend(loc="upper left")
    ax.set_xlabel("body size")
    ax.set_ylabel("food eaten per episode")
    ax.set_title(f"Food vs size ({episodes['episode'].nunique()} episodes)")


PANELS = [
    Panel("fig3", "M", food_vs_size, {"episodes": "assays/patchy4/episodes.parquet"},
          "Food eaten per agent-episode against body size, selected seed, 4-agent patchy 70x70 arena."),
]
