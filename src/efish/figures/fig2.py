"""Fig 2: homing towards a frozen, emitting target (SPEC 11, 13)."""

from __future__ import annotations

import pandas as pd

from .panel import Panel
from .style import agent_colour, missing

CONDITION_STYLE = {"electric": "-", "raycast": "--"}
MAX_EPISODES_DRAWN = 8


def trajectories(tables: dict[str, pd.DataFrame], ax) -> None:
    """Panel B: the homer's paths (agent 1) to the target (agent 0, star), electric solid, ray-casting dashed."""
    steps = tables["steps"]
    if steps.empty:
        missing(ax, "homing steps table is empty")
        return
    for condition, linestyle in CONDITION_STYLE.items():
        runs = steps[steps["condition"] == condition]
        for episode in sorted(runs["episode"].unique())[:MAX_EPISODES_DRAWN]:
            run = runs[runs["episode"] == episode].sort_values("t")
            homer, target = run[run["agent"] == 1], run[run["agent"] == 0]
            ax.plot(homer["x_cm"], homer["y_cm"], linestyle, color=agent_colour(episode), lw=0.8)
            ax.plot(homer["x_cm"].iloc[:1], homer["y_cm"].iloc[:1], "o", color=agent_colour(episode), ms=3)
            ax.plot(target["x_cm"].iloc[:1], target["y_cm"].iloc[:1], "*", color=agent_colour(episode), ms=8)
    absent = [c for c in CONDITION_STYLE if c not in set(steps["condition"])]
    if absent:
        ax.text(0.02, 0.98, "no data: " + ", ".join(absent) + " condition not run", transform=ax.transAxes,
                va="top", fontsize=6)
    ax.set_aspect("equal")
    ax.set_xlabel("x (cm)")
    ax.set_ylabel("y (cm)")
    ax.set_title("Homing trajectories")


PANELS = [
    Panel("fig2", "B", trajectories, {"steps": "assays/homing/steps.parquet"},
          "Homing trajectories of the homing policy towards a frozen, always-emitting target (SPEC 11)."),
]
