"""One look for every panel: colours per agent and per receptor class, fixed once."""

from __future__ import annotations

from contextlib import contextmanager

AGENT_COLOURS = ("#0072B2", "#D55E00", "#009E73", "#CC79A7", "#E69F00", "#56B4E9", "#F0E442", "#000000")
RECEPTOR_COLOURS = {"mormyromast": "#0072B2", "ampullary": "#009E73", "knollenorgan": "#D55E00"}
SELECTED_COLOUR = "#D55E00"
NEUTRAL_COLOUR = "#7f7f7f"

RC_PARAMS = {
    "figure.dpi": 100, "savefig.dpi": 200, "font.size": 8, "axes.titlesize": 9, "axes.labelsize": 8,
    "axes.spines.top": False, "axes.spines.right": False, "legend.frameon": False, "legend.fontsize": 7,
    "xtick.labelsize": 7, "ytick.labelsize": 7, "lines.linewidth": 1.0,
}


def agent_colour(agent: int) -> str:
    """The colour of agent ``agent`` in every panel."""
    return AGENT_COLOURS[int(agent) % len(AGENT_COLOURS)]


@contextmanager
def panel_style():
    """Headless backend and the shared rc parameters, restored afterwards."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    with plt.rc_context(RC_PARAMS):
        yield plt


def missing(ax, what: str) -> None:
    """Say on the panel that its data is not there, instead of drawing anything made up."""
    ax.text(0.5, 0.5, f"no data:\n{what}", ha="center", va="center", transform=ax.transAxes,
            color=NEUTRAL_COLOUR, fontsize=8, wrap=True)
    ax.set_xticks([])
    ax.set_yticks([])
