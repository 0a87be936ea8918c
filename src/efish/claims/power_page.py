"""The page of what a decisive verdict costs (``claims/power.md``, written by ``efish power``): the planner's table
of :mod:`efish.claims.planner` in Markdown, with what a seed costs in this run and how to read the columns."""

from __future__ import annotations

import numpy as np
import pandas as pd

from .planner import RunCosts, target_line
from .power import MAX_SEEDS, TARGET


def _number(value, digits: int = 3) -> str:
    return "" if pd.isna(value) else f"{value:.{digits}g}"


def _chance(value) -> str:
    return "" if pd.isna(value) else f"{value:.0%}"


def _seeds(value, hours) -> str:
    """Seeds for the target and their CPU-hours; beyond reach where no design of MAX_SEEDS seeds reaches it."""
    if pd.isna(value):
        return ""
    return f"{int(value)} ({hours:.3g} h)" if np.isfinite(hours) else str(int(value))


def power_markdown(plan: pd.DataFrame, costs: RunCosts, header: str, alpha: float) -> str:
    """The page: a header, what one seed costs, how to read the table, and one row per part of ``plan``
    (:data:`efish.claims.planner.PLAN_COLUMNS`)."""
    seed_h = costs.design_hours(1)
    price = (f"One more seed costs {seed_h:.3g} CPU-hours in this run: training {costs.train_s / 3600:.3g} h, "
             f"selection {costs.selection_s / 3600:.3g} h, reruns of the claims' assays {costs.rerun_s / 3600:.3g} h "
             f"(means over {costs.seeds_timed}; Snakemake's benchmark files of this run's jobs)."
             if np.isfinite(seed_h) else f"The designs are not priced: {costs.seeds_timed}.")
    planned = plan["tau"].notna() & plan["now_holds_at_2delta"].notna()
    lines = ["# What a decisive verdict costs\n", header, "", price, "",
             f"For every part the recipe decides over seeds: the spread of its effect over this run's seeds split "
             f"into between seeds (tau) and within a seed's episodes (sigma, per episode), and from them the chance "
             f"that the recipe's verdict (alpha {alpha:g}, Holm family counted) settles now and the {target_line()}. "
             f"These are planning figures, not verdicts: nothing here changes a claim. An empty cell: the part "
             f"could not be planned (its note says why) or no design of up to {MAX_SEEDS} seeds reaches "
             f"{TARGET:.0%}.", "",
             f"{int(planned.sum())} of {len(plan)} parts planned.", "",
             "| claim | part | delta | seeds | effect | tau | sigma | holds at 2 delta: now | seeds (CPU-h) "
             "| absent at 0: now | seeds (CPU-h) | note |",
             "|---|---|---|---|---|---|---|---|---|---|---|---|"]
    for row in plan.itertuples(index=False):
        cells = [row.claim, row.part, _number(row.delta), str(int(row.seeds)), _number(row.effect),
                 _number(row.tau), _number(row.sigma), _chance(row.now_holds_at_2delta),
                 _seeds(row.seeds_holds_at_2delta, row.cpu_hours_holds_at_2delta), _chance(row.now_absent_at_0),
                 _seeds(row.seeds_absent_at_0, row.cpu_hours_absent_at_0), row.note]
        lines.append("| " + " | ".join(str(c).replace("|", "/") for c in cells) + " |")
    return "\n".join(lines) + "\n"


def headline(plan: pd.DataFrame, costs: RunCosts) -> str:
    """One line for a terminal: how many parts reach the target with the run's seeds, and the largest design
    named (in seeds and CPU-hours) for the scenario of an effect of twice delta."""
    k = plan["seeds_holds_at_2delta"]
    plannable = int(plan["now_holds_at_2delta"].notna().sum())
    if not plannable:
        return f"no part could be planned ({len(plan)} parts): see the notes"
    now = int((plan["now_holds_at_2delta"] >= TARGET).sum())
    reach = f"{int(k.notna().sum())} of {plannable} plannable parts reach it"
    most = ""
    if k.notna().any():
        hours = costs.design_hours(int(np.nanmax(k)))
        most = f" with {int(np.nanmax(k))} seeds" + (f" ({hours:.3g} CPU-hours)" if np.isfinite(hours) else "")
    return f"{now} of {len(plan)} parts reach {TARGET:.0%} with this run's seeds if the effect is twice delta; {reach}{most}"
