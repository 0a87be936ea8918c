"""What a decisive verdict costs (``efish power --figures``): for each claim, the chance that its recipe verdict
settles against the CPU-hours of a design of more seeds, the science's counterpart of the benchmarks'
accuracy-against-time figure.

Two axes, one per planner scenario (:data:`efish.claims.power.SCENARIOS`): left, the chance of "holds" if every
part's true effect is twice its delta; right, of "absent" (for a "no difference" part, "holds") if there is no
effect. One line per claim: its weakest part's chance at each design (:func:`efish.claims.planner.claim_curves`,
an upper bound on the claim's), a ring at the run's own number of seeds, a dashed line at the target. Claims none of
whose parts can be planned are named in a note instead of drawn. A homing claim's seeds are draws of the homing
recipes, priced as such (:meth:`efish.claims.planner.RunCosts.design_hours`): the top axis counts a foraging
claim's seeds.

Reads the tables of :mod:`efish.claims.planner`; no simulator, no torch.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd
from matplotlib.ticker import FuncFormatter, LogLocator, NullFormatter

from ..claims.planner import SCENARIO_KEYS, claim_curves
from ..claims.power import TARGET
from .render import save_figure
from .style import missing, panel_style

#: Each scenario's axes title.
TITLES = {"holds_at_2delta": "true effect 2 delta: chance of holds",
          "absent_at_0": "no effect: chance of absent"}
FONT = 8.0


def _plain_log_ticks(axis) -> None:
    """Ticks at 1, 2 and 5 of every decade, written as plain numbers (0.2, 5, 10), none between."""
    axis.set_major_locator(LogLocator(subs=(1.0, 2.0, 5.0)))
    axis.set_major_formatter(FuncFormatter(lambda v, _: f"{v:g}"))
    axis.set_minor_formatter(NullFormatter())


def plot_power(curves: pd.DataFrame, plan: pd.DataFrame, stem: Path, title: str) -> list[Path]:
    """Draw the figure from :func:`efish.claims.planner.power_curves`' ``curves`` and the plan table ``plan`` (its
    ``seeds`` column gives the run's design); writes ``stem``.png and .pdf and returns their paths."""
    by_claim = claim_curves(curves) if len(curves) else curves
    claims = list(dict.fromkeys(plan["claim"]))
    drawn = list(dict.fromkeys(by_claim["claim"])) if len(by_claim) else []
    now = plan.groupby("claim", sort=False)["seeds"].max()
    draw_claims = set(plan.loc[plan["draws"].fillna(False).astype(bool), "claim"]) if "draws" in plan else set()
    priced = bool(len(by_claim)) and bool(np.isfinite(by_claim["cpu_hours"]).all())
    x = "cpu_hours" if priced else "seeds"
    with panel_style() as plt:
        fig, axes = plt.subplots(1, 2, figsize=(10.0, 4.4), sharey=True, layout="constrained")
        colours = plt.get_cmap("tab20")
        for ax, key in zip(axes, SCENARIO_KEYS, strict=True):
            ax.set_title(TITLES[key], fontsize=FONT + 1)
            if not drawn:
                missing(ax, "no part has two seeds with an effect to plan from")
                continue
            for i, claim in enumerate(drawn):
                rows = by_claim[by_claim["claim"] == claim]
                colour = colours(i % 20)
                ax.plot(rows[x], rows[key], color=colour, lw=1.2, label=claim)
                at = rows[rows["seeds"] == now.get(claim)]
                ax.plot(at[x], at[key], "o", mfc="none", color=colour, ms=6)
            ax.axhline(TARGET, color="black", ls="--", lw=0.8)
            ax.set_xscale("log")
            _plain_log_ticks(ax.xaxis)
            if priced:  # a design's CPU-hours are its seeds times one seed's: the top axis counts the seeds
                foraging = by_claim[~by_claim["claim"].isin(draw_claims)]
                rows = foraging if len(foraging) else by_claim
                per_seed = float(rows["cpu_hours"].iloc[0] / rows["seeds"].iloc[0])
                top = ax.secondary_xaxis("top", functions=(lambda h, c=per_seed: h / c,
                                                           lambda k, c=per_seed: k * c))
                top.set_xlabel("seeds of a foraging claim (the homing claims' draws priced apart)"
                               if draw_claims & set(drawn) and len(foraging) else "seeds", fontsize=FONT)
                _plain_log_ticks(top.xaxis)
                top.tick_params(labelsize=FONT - 1)
            ax.set_ylim(0, 1.02)
            ax.set_xlabel("CPU-hours of the design (this run's measured job times)" if priced
                          else "seeds (not priced: this run has no training benchmark)", fontsize=FONT)
            ax.tick_params(labelsize=FONT - 1)
        axes[0].set_ylabel("chance the claim's verdict settles (weakest part)", fontsize=FONT)
        if drawn:  # beside the axes: inside, 20 claims would hide the curves
            fig.legend(*axes[0].get_legend_handles_labels(), fontsize=FONT - 1, ncol=1 + len(drawn) // 12,
                       loc="outside right upper", title="claim (ring: this run)", title_fontsize=FONT - 1)
        unplanned = [c for c in claims if c not in drawn]
        fig.suptitle(title + (f"\nnot plannable (fewer than 2 seeds with an effect): {', '.join(unplanned)}"
                              if unplanned else ""), fontsize=FONT + 1)
        paths = save_figure(fig, stem)
        plt.close(fig)
    return paths
