"""The heatmap of ``efish compare-claims`` over N runs: claims as rows, runs as columns, each cell coloured by the
run's headline verdict with its effect printed in it. The table it draws is :func:`efish.claims.grid.claims_grid`."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd

from ..claims.grid import headline
from ..io import atomic_path
from .learning import VERDICT_COLOURS
from .style import panel_style

SEED_MARK = "*"  # beside a cell's effect: the selected seed's verdict, not the recipe's


def heatmap_figure(grid: pd.DataFrame, runs: list[str], plt):
    """The heatmap of ``grid``: claims as rows, runs as columns (``runs``: their labels in the grid), each cell
    coloured by the run's headline verdict (:func:`efish.claims.grid.headline`) with its effect printed in it (blank
    where the claim has none or was not run; :data:`SEED_MARK` where the verdict is the selected seed's)."""
    from matplotlib.patches import Patch

    verdicts, effects, recipe = headline(grid, runs)
    colours = {**VERDICT_COLOURS, "-": "white"}
    fig, ax = plt.subplots(figsize=(1.6 + 1.1 * len(runs), 0.9 + 0.3 * len(verdicts)))
    for i, claim in enumerate(verdicts.index):
        for j, run in enumerate(runs):
            verdict, effect = verdicts.at[claim, run], effects.at[claim, run]
            ax.add_patch(plt.Rectangle((j, i), 1, 1, facecolor=colours.get(verdict, "white"), edgecolor="white",
                                       label=f"{claim} {run}"))
            text = f"{effect:.2g}" if pd.notna(effect) and np.isfinite(effect) else ""
            if verdict not in ("-", "not run") and not recipe.at[claim, run]:
                text += SEED_MARK  # the selected seed's verdict: the recipe did not decide this claim
            if text:
                ax.text(j + 0.5, i + 0.5, text, ha="center", va="center", fontsize=7)
    ax.set_xlim(0, len(runs))
    ax.set_ylim(len(verdicts), 0)
    ax.set_xticks(np.arange(len(runs)) + 0.5, runs, rotation=30, ha="right", fontsize=7)
    ax.set_yticks(np.arange(len(verdicts)) + 0.5, verdicts.index, fontsize=7)
    ax.tick_params(length=0)
    for side in ax.spines.values():
        side.set_visible(False)
    shown = [v for v in VERDICT_COLOURS if (verdicts == v).any().any()]
    ax.legend([Patch(facecolor=VERDICT_COLOURS[v]) for v in shown], shown, fontsize=7, frameon=False,
              loc="upper left", bbox_to_anchor=(1.0, 1.0))
    ax.set_title(f"each run's verdict and effect: the recipe's over its top seeds,\n"
                 f"the selected seed's where the recipe did not decide ({SEED_MARK})", fontsize=8)
    fig.tight_layout()
    return fig


def draw_heatmap(grid: pd.DataFrame, runs: list[str], path: Path) -> None:
    """:func:`heatmap_figure` as a PNG at ``path``, written atomically."""
    with panel_style() as plt:
        fig = heatmap_figure(grid, runs, plt)
        try:
            path.parent.mkdir(parents=True, exist_ok=True)
            with atomic_path(path) as tmp:
                fig.savefig(tmp, format="png", dpi=150)
        finally:
            plt.close(fig)
