"""Fig 2: homing towards a frozen, always-emitting target (docs/methods/assays.md#assay-homing,
docs/methods/figures.md#panels).

Agent 0 is the target, agent 1 the homer (the homing assay's layout); the
conditions are ``electric`` (the homing policy with electric senses) and
``raycast`` (the ray-casting policy).
"""

from __future__ import annotations

import numpy as np
import pandas as pd

from .. import layout
from ..senses import SENSES
from .panel import Panel
from .style import RECEPTOR_COLOURS, condition_palette, finite, missing, stars_for

TARGET, HOMER = 0, 1
CONDITIONS = ("electric", "raycast")
CONDITION_STYLE = {"electric": "-", "raycast": "--"}
MAX_EPISODES_DRAWN = 8
#: error-angle channel of the analysis tables -> receptor class of the style palette
CHANNEL_RECEPTOR = {s.short: s.name for s in SENSES}
#: the target's intrinsic and EOD dipoles share its axis, so the Ampullary and Knollenorgan error angles nearly
#: coincide: distinct dashes and markers keep both lines visible where they overlap
CHANNEL_STYLE = {s.short: (s.line, s.marker) for s in SENSES}


def _palette() -> dict:
    return condition_palette(CONDITIONS, control="raycast")


def scene(tables: dict[str, pd.DataFrame], ax) -> None:
    """Panel A: where the test episodes start: the target (star, heading arrow = its dipole axis) and the
    homer's start positions, one dot per episode, from the first step of each electric episode."""
    steps = tables["steps"]
    first = steps[(steps["condition"] == "electric")].sort_values("t").groupby(["episode", "agent"]).head(1)
    if first.empty:
        missing(ax, "no electric homing episode in the steps table")
        return
    homer, target = first[first["agent"] == HOMER], first[first["agent"] == TARGET]
    colour = _palette()["electric"]
    for _, row in target.iterrows():
        ax.plot([row["x_cm"], homer.loc[homer["episode"] == row["episode"], "x_cm"].squeeze()],
                [row["y_cm"], homer.loc[homer["episode"] == row["episode"], "y_cm"].squeeze()],
                color="0.85", lw=0.4, zorder=1)
    ax.scatter(homer["x_cm"], homer["y_cm"], s=8, color=colour, label="homer start", zorder=2)
    ax.scatter(target["x_cm"], target["y_cm"], s=40, marker="*", color="black", label="target", zorder=3)
    ax.quiver(target["x_cm"], target["y_cm"], np.cos(target["heading_rad"]), np.sin(target["heading_rad"]),
              angles="xy", scale_units="inches", scale=6, width=0.004, color="black", zorder=3)
    ax.set_aspect("equal")
    ax.set_xlabel("x (cm)")
    ax.set_ylabel("y (cm)")
    ax.set_title(f"Homing starts ({homer['episode'].nunique()} episodes)")
    ax.legend(loc="upper left", bbox_to_anchor=(1.02, 1.0), fontsize=6, handletextpad=0.2, frameon=False)


def trajectories(tables: dict[str, pd.DataFrame], ax) -> None:
    """Panel B: the homer's paths to the target (star), electric solid, ray-casting dashed, up to
    MAX_EPISODES_DRAWN per condition; the tortuosity test (electric vs ray casting) from the perception table."""
    steps = tables["steps"]
    if steps.empty:
        missing(ax, "homing steps table is empty")
        return
    palette = _palette()
    for condition, linestyle in CONDITION_STYLE.items():
        runs = steps[steps["condition"] == condition]
        for i, episode in enumerate(sorted(runs["episode"].unique())[:MAX_EPISODES_DRAWN]):
            run = runs[runs["episode"] == episode].sort_values("t")
            homer, target = run[run["agent"] == HOMER], run[run["agent"] == TARGET]
            ax.plot(homer["x_cm"], homer["y_cm"], linestyle, color=palette[condition], lw=0.8,
                    label=condition if i == 0 else None)
            ax.plot(homer["x_cm"].iloc[:1], homer["y_cm"].iloc[:1], "o", color=palette[condition], ms=2.5)
            ax.plot(target["x_cm"].iloc[:1], target["y_cm"].iloc[:1], "*", color="black", ms=6)
    absent = [c for c in CONDITION_STYLE if c not in set(steps["condition"])]
    note = ("no data: " + ", ".join(absent) + " not run; ") if absent else ""
    tortuosity = stars_for(tables["perception"], measure="tortuosity")
    # beside the arena, not on it: trajectories fill the whole square
    ax.text(1.02, 0.70, f"{note}tortuosity,\nelectric vs\nray casting: {tortuosity}", transform=ax.transAxes,
            va="top", fontsize=6)
    ax.set_aspect("equal")
    ax.set_xlabel("x (cm)")
    ax.set_ylabel("y (cm)")
    ax.set_title("Homing trajectories")
    ax.legend(loc="upper left", bbox_to_anchor=(1.02, 1.0), fontsize=6, frameon=False)


def error_polar(tables: dict[str, pd.DataFrame], ax) -> None:
    """Panel C (polar): density of the error angle (heading minus the local direction of the target's field,
    per receptor class) of the electric homer, from the homing analysis's error histogram."""
    hist = tables["error_histogram"]
    hist = hist[(hist["condition"] == "electric") & np.isfinite(hist["density"])] if "density" in hist else hist[:0]
    if hist.empty:
        reason = tables["error_histogram"].get("reason", pd.Series(["no electric error angles"])).iloc[0]
        missing(ax, reason or "no electric error angles")
        return
    for channel, sub in hist.groupby("channel", sort=True):
        centres = (sub["bin_lo_rad"] + sub["bin_hi_rad"]).to_numpy() / 2
        closed = np.r_[centres, centres[:1]]
        ax.plot(closed, np.r_[sub["density"].to_numpy(), sub["density"].iloc[:1]], CHANNEL_STYLE[channel][0],
                color=RECEPTOR_COLOURS[CHANNEL_RECEPTOR[channel]], label=CHANNEL_RECEPTOR[channel], lw=1.0)
    ax.set_theta_zero_location("N")  # 0 = heading along the field line, at the top
    top = float(hist["density"].max())
    ax.set_rticks(np.round(np.linspace(0, top, 4)[1:], 1))  # three radial labels, not a crowd at the centre
    ax.set_rlabel_position(22.5)
    # units in the title: polar axis labels collide with the angle ticks and the legend
    ax.set_title("Error angle (deg): density (1/rad)")
    ax.tick_params(labelsize=6, pad=0)
    ax.legend(loc="upper center", bbox_to_anchor=(0.5, -0.12), ncol=3, fontsize=6, columnspacing=0.8)


def error_vs_time(tables: dict[str, pd.DataFrame], ax) -> None:
    """Panel D: mean |error angle| (+- SEM) against normalised episode time per receptor class, electric
    homer, from the homing analysis's error_vs_time table."""
    table = tables["error_vs_time"]
    table = table[table["condition"] == "electric"] if "condition" in table else table[:0]
    if not len(finite(table.get("mean_abs_err_rad", []))):
        reason = tables["error_vs_time"].get("reason", pd.Series(["no electric error angles"])).iloc[0]
        missing(ax, reason or "no electric error angles")
        return
    for channel, sub in table.groupby("channel", sort=True):
        colour = RECEPTOR_COLOURS[CHANNEL_RECEPTOR[channel]]
        line, marker = CHANNEL_STYLE[channel]
        ax.plot(sub["t_norm_mid"], sub["mean_abs_err_rad"], ls=line, marker=marker, ms=2.5, color=colour,
                label=CHANNEL_RECEPTOR[channel])
        sem = sub["sem_abs_err_rad"].fillna(0)
        ax.fill_between(sub["t_norm_mid"], sub["mean_abs_err_rad"] - sem, sub["mean_abs_err_rad"] + sem,
                        color=colour, alpha=0.2, lw=0)
    ax.axhline(np.pi / 2, color="0.6", lw=0.5, ls=":")  # the mean |error| of a uniform angle
    ax.set_xlim(0, 1)
    ax.set_xlabel("normalised episode time")
    ax.set_ylabel("|error angle| (rad)")
    ax.set_title("Error angle over the episode")
    ax.legend(loc="best", fontsize=6)


HOMING = layout.assay_table("homing", "steps")


def _analysis(table: str) -> str:
    return layout.analysis_table("homing", "homing", table)


PANELS = [
    Panel("fig2", "A", scene, {"steps": HOMING},
          "Homing assay (docs/methods/assays.md#assay-homing): start positions of the homer (dots) and the frozen, "
          "always-emitting target (star; the arrow is its heading, the axis of its dipole) in the electric test "
          "episodes; homing steps table."),
    Panel("fig2", "B", trajectories, {"steps": HOMING, "perception": _analysis("perception")},
          "Homing trajectories of the homer, electric senses (solid) vs ray casting (dashed), homing assay; stars: "
          "Mann-Whitney test of tortuosity (path length / displacement) from the homing analysis's perception table."),
    Panel("fig2", "C", error_polar, {"error_histogram": _analysis("error_histogram")},
          "Polar density of the error angle (heading minus the local direction of the target's field) per receptor "
          "class, electric homer, homing assay; homing analysis's error_histogram table.", projection="polar"),
    Panel("fig2", "D", error_vs_time, {"error_vs_time": _analysis("error_vs_time")},
          "Mean absolute error angle (+- SEM) against normalised episode time per receptor class, electric homer; "
          "the dotted line is the mean of a uniform angle (pi/2); homing analysis's error_vs_time table."),
]
