"""One look for every panel: colours per agent, size class, receptor class and condition, fixed once.

Every panel module takes its colours from here, so that an agent, a size
class or a receptor class has the same colour in every figure. Box, strip
and heat-map panels use seaborn with these palettes; :func:`panel_style`
sets a print-size theme (one column = 3.5 in, 7-8 pt text).
"""

from __future__ import annotations

from collections.abc import Iterable
from contextlib import contextmanager

import numpy as np
import pandas as pd

AGENT_COLOURS = ("#0072B2", "#D55E00", "#009E73", "#CC79A7", "#E69F00", "#56B4E9", "#F0E442", "#000000")
RECEPTOR_COLOURS = {"mormyromast": "#0072B2", "ampullary": "#009E73", "knollenorgan": "#D55E00"}
SELECTED_COLOUR = "#D55E00"
NEUTRAL_COLOUR = "#7f7f7f"
#: The control (first) condition of an assay is always grey; the others take CONDITION_COLOURS in order.
CONTROL_COLOUR = "#7f7f7f"
CONDITION_COLOURS = ("#0072B2", "#D55E00", "#009E73", "#CC79A7", "#E69F00", "#56B4E9", "#F0E442")
#: Size classes from small to large (ranks within an episode, or the one-patch A-vs-B classes): one
#: sequential palette, light = small, dark = large.
SIZE_CLASS_CMAP = "viridis_r"
ONEPATCH_CLASS_COLOURS = {"A_lt_B": "#440154", "A_eq_B": "#21918c", "A_gt_B": "#fde725",
                          "A_alone": "#7f7f7f", "B_alone": "#bfbfbf"}
#: Sequential colour map of every heat map (bite matrices, field maps use their own diverging one).
HEATMAP_CMAP = "rocket_r"
FIELD_CMAP = "RdBu_r"

RC_PARAMS = {
    "figure.dpi": 100, "savefig.dpi": 200, "font.size": 8, "axes.titlesize": 9, "axes.labelsize": 8,
    "axes.spines.top": False, "axes.spines.right": False, "legend.frameon": False, "legend.fontsize": 7,
    "xtick.labelsize": 7, "ytick.labelsize": 7, "lines.linewidth": 1.0,
}


def agent_colour(agent: int) -> str:
    """The colour of agent ``agent`` in every panel."""
    return AGENT_COLOURS[int(agent) % len(AGENT_COLOURS)]


def size_class_colours(n: int) -> list:
    """``n`` colours for size classes 0 (smallest) .. n-1 (largest), the same ramp in every figure."""
    import matplotlib

    cmap = matplotlib.colormaps[SIZE_CLASS_CMAP]
    return [cmap(0.15 + 0.7 * i / max(n - 1, 1)) for i in range(n)]


def condition_palette(conditions: Iterable, control=None) -> dict:
    """Colour per condition: ``control`` (default: the first) grey, the rest in CONDITION_COLOURS order."""
    conditions = list(dict.fromkeys(conditions))
    control = conditions[0] if control is None and conditions else control
    others = [c for c in conditions if c != control]
    palette = {c: CONDITION_COLOURS[i % len(CONDITION_COLOURS)] for i, c in enumerate(others)}
    if control in conditions:
        palette[control] = CONTROL_COLOUR
    return palette


def stars_for(stats: pd.DataFrame, **where) -> str:
    """The ``stars`` of the one statistic row matching ``where`` (e.g. ``group="M_A"``), ``"n/a"`` if absent.

    Panels never recompute a test: they read its stars from the analysis's statistic table.
    """
    rows = stats
    for column, value in where.items():
        if column not in rows.columns:
            return "n/a"
        rows = rows[rows[column] == value]
    return str(rows["stars"].iloc[0]) if len(rows) and "stars" in rows.columns else "n/a"


def annotate_stars(ax, x: float, y: float, text: str, x2: float | None = None) -> None:
    """Stars above a group at ``x`` (or a bracket from ``x`` to ``x2``) at data height ``y``."""
    if x2 is not None:
        ax.plot([x, x, x2, x2], [y * 0.98, y, y, y * 0.98], color="black", lw=0.6)
        x = (x + x2) / 2
    ax.text(x, y, text, ha="center", va="bottom", fontsize=7)


@contextmanager
def panel_style():
    """Headless backend and the shared rc parameters, restored afterwards."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    import seaborn as sns

    with plt.rc_context(sns.axes_style("ticks")), plt.rc_context(RC_PARAMS):
        yield plt


def missing(ax, what: str) -> None:
    """Say on the panel that its data is not there, instead of drawing anything made up."""
    ax.text(0.5, 0.5, f"no data:\n{what}", ha="center", va="center", transform=ax.transAxes,
            color=NEUTRAL_COLOUR, fontsize=8, wrap=True)
    ax.set_xticks([])
    ax.set_yticks([])


def finite(values) -> np.ndarray:
    """The finite entries of ``values`` as floats (NaN rows of analysis tables carry a ``reason`` instead)."""
    x = np.asarray(values, dtype=float)
    return x[np.isfinite(x)]
