"""The page of what a decisive verdict costs (``claims/power.md``, written by ``efish power``): the planner's table
of :mod:`efish.claims.planner` in Markdown, with what a seed costs in this run and how to read the columns."""

from __future__ import annotations

import numpy as np
import pandas as pd

from .planner import MORE_EPISODES, RunCosts, target_line
from .power import MAX_SEEDS, TARGET


def _number(value, digits: int = 3) -> str:
    return "" if pd.isna(value) else f"{value:.{digits}g}"


def _chance(value) -> str:
    return "" if pd.isna(value) else f"{value:.0%}"


def _seeds(value, hours) -> str:
    """Seeds (or episodes) for the target and their CPU-hours; empty where no design reaches it."""
    if pd.isna(value):
        return ""
    return f"{int(value)} ({hours:.3g} h)" if np.isfinite(hours) else str(int(value))


def _own(row, key: str) -> str:
    """The selected seed's own test in one cell: its chance now and the episodes per condition (CPU-hours) that
    reach the target, e.g. "31%; 27 (0.41 h)"."""
    now = _chance(getattr(row, f"own_now_{key}"))
    return f"{now}; {_seeds(getattr(row, f'own_episodes_{key}'), getattr(row, f'own_cpu_hours_{key}'))}" if now else ""


def power_markdown(plan: pd.DataFrame, costs: RunCosts, header: str, alpha: float,
                   summary: pd.DataFrame | None = None) -> str:
    """The page: a header, what one seed costs, one line per claim (``summary``, :func:`claim_summary`, where the
    run has its claims table), how to read the table, and one row per part of ``plan``
    (:data:`efish.claims.planner.PLAN_COLUMNS`)."""
    seed_h = costs.design_hours(1)
    price = (f"One more seed costs {seed_h:.3g} CPU-hours in this run: training {costs.train_s / 3600:.3g} h, "
             f"selection {costs.selection_s / 3600:.3g} h, reruns of the claims' assays {costs.rerun_s / 3600:.3g} h "
             f"(means over {costs.seeds_timed}; Snakemake's benchmark files of this run's jobs)."
             if np.isfinite(seed_h) else f"The designs are not priced: {costs.seeds_timed}.")
    draw_h = (costs.draw_train_s + costs.draw_rerun_s) / 3600
    if np.isfinite(seed_h) and np.isfinite(draw_h):
        price += (f" One more draw of the homing recipes, which the homing claims are decided over, costs "
                  f"{draw_h:.3g} CPU-hours: training them {costs.draw_train_s / 3600:.3g} h, a rerun of "
                  f"{', '.join(costs.drawn_assays)} with them {costs.draw_rerun_s / 3600:.3g} h.")
    if np.isfinite(seed_h) and costs.run_s > 0:
        price += f" The whole run cost {costs.run_s / 3600:.3g} CPU-hours."
    planned = plan["tau"].notna() & plan["now_holds_at_2delta"].notna()
    by_claim = [] if summary is None else ["## By claim\n", *[f"- {line}" for line in summary["line"]], "",
                                            "## By part\n"]
    lines = ["# What a decisive verdict costs\n", header, "", price, "", *by_claim,
             f"For every part the recipe decides over seeds: the spread of its effect over this run's seeds split "
             f"into between seeds (tau) and within a seed's episodes (sigma, per episode), and from them the chance "
             f"that the recipe's verdict (alpha {alpha:g}, Holm family counted) settles now and the {target_line()}. "
             f"These are planning figures, not verdicts: nothing here changes a claim. An empty cell: the part "
             f"could not be planned (its note says why) or no design of up to {MAX_SEEDS} seeds reaches "
             f"{TARGET:.0%}. The selected seed's own verdict, decided by its part's own test over its episodes, is "
             f"planned from the same sigma: its chance now, and the episodes per condition (CPU-hours of rerunning the "
             f"claims' assays at them) that reach {TARGET:.0%}.", "",
             f"{int(planned.sum())} of {len(plan)} parts planned.", "",
             "| claim | part | delta | seeds | effect | tau | sigma | holds at 2 delta: now | seeds (CPU-h) "
             f"| the same at {MORE_EPISODES}x episodes | absent at 0: now | seeds (CPU-h) | selected seed's test "
             "| its holds at 2 delta: now; episodes (CPU-h) | its absent at 0: now; episodes (CPU-h) | note |",
             "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|"]
    stages = "trend" in plan.columns
    if stages:
        lines[-2] = lines[-2].rstrip(" |") + " | along training (env steps: effect) | trend |"
        lines[-1] += "---|---|"
    for row in plan.itertuples(index=False):
        cells = [row.claim, row.part, _number(row.delta), str(int(row.seeds)), _number(row.effect),
                 _number(row.tau), _number(row.sigma), _chance(row.now_holds_at_2delta),
                 _seeds(row.seeds_holds_at_2delta, row.cpu_hours_holds_at_2delta),
                 _seeds(row.seeds_holds_at_2delta_more_episodes, row.cpu_hours_holds_at_2delta_more_episodes),
                 _chance(row.now_absent_at_0),
                 _seeds(row.seeds_absent_at_0, row.cpu_hours_absent_at_0), row.own_test,
                 _own(row, "holds_at_2delta"), _own(row, "absent_at_0"), row.note,
                 *([row.stage_effects, row.trend] if stages else [])]
        lines.append("| " + " | ".join(str(c).replace("|", "/") for c in cells) + " |")
    return "\n".join(lines) + "\n"


#: The columns of :func:`claim_summary`: per claim, its recipe verdict and parts tally, its undecided deciding parts,
#: and the design that would decide it in each scenario with its CPU-hours and its multiple of this run's.
CLAIM_SUMMARY_COLUMNS = ["claim", "recipe_verdict", "recipe_parts", "undecided", "unplanned", "seeds_holds_at_2delta",
                         "cpu_hours_holds_at_2delta", "runs_holds_at_2delta", "line"]
UNDECIDED = "inconclusive"


def _decider(plan_rows: pd.DataFrame, costs: RunCosts) -> tuple[float, float, float, str]:
    """(seeds, CPU-hours, multiple of this run, words) of the design that settles every one of ``plan_rows`` in the
    scenario of an effect of twice delta: the most seeds any one of them needs."""
    k = plan_rows["seeds_holds_at_2delta"]
    n = len(plan_rows)
    parts = f"its {n} inconclusive part{'s' * (n > 1)}"
    if k.isna().any():
        beyond = ", ".join(f"'{part}'" for part in plan_rows.loc[k.isna()].index.get_level_values("part"))
        which = f"{beyond} ({int(k.isna().sum())} of {parts})" if n > 1 else parts
        return np.nan, np.nan, np.nan, (f"no design of up to {MAX_SEEDS:,} seeds settles {which}, even at twice "
                                        "delta: the spread between seeds dwarfs delta")
    seeds = int(k.max())
    hours = float(plan_rows["cpu_hours_holds_at_2delta"].iloc[int(np.argmax(k.to_numpy()))])  # seeds or draws
    runs = hours * 3600 / costs.run_s if np.isfinite(hours) and costs.run_s > 0 else np.nan
    priced = (f" ({hours:.3g} CPU-hours here" + (f", {runs:.2g}x this run" if np.isfinite(runs) else "") + ")"
              if np.isfinite(hours) else "")
    unit = "draws of the homing recipes" if plan_rows["draws"].astype(bool).all() else "seeds"
    return seeds, hours, runs, f"about {seeds} {unit}{priced} would settle {parts} if each effect were twice its delta"


def claim_summary(plan: pd.DataFrame, claims: pd.DataFrame, recipe: pd.DataFrame, costs: RunCosts) -> pd.DataFrame:
    """:data:`CLAIM_SUMMARY_COLUMNS`, one row per claim of ``claims`` (the run's claims table, with the recipe's
    columns): for a claim the recipe left inconclusive, the design that would settle its inconclusive deciding
    parts (``recipe``: recipe_parts.parquet) if each part's true effect were twice its delta."""
    rows = []
    by_part = plan.set_index(["claim", "part"])
    for claim in claims.itertuples(index=False):
        verdict = getattr(claim, "recipe_verdict", None)
        row = dict.fromkeys(CLAIM_SUMMARY_COLUMNS, np.nan) | {
            "claim": claim.claim, "recipe_verdict": verdict, "recipe_parts": getattr(claim, "recipe_parts", ""),
            "undecided": 0, "unplanned": 0}
        parts = recipe[(recipe["claim"] == claim.claim) & recipe["decides"].astype(bool)
                       & (recipe["verdict"] == UNDECIDED)]
        keys = [(claim.claim, part) for part in parts["part"] if (claim.claim, part) in by_part.index]
        planned = by_part.loc[keys] if keys else by_part.iloc[:0]
        planned = planned[planned["now_holds_at_2delta"].notna()]
        row.update(undecided=len(parts), unplanned=len(parts) - len(planned))
        words = f"{claim.claim}: recipe {verdict or 'not decided'}" + (f" ({row['recipe_parts']})"
                                                                        if row["recipe_parts"] else "")
        if verdict == UNDECIDED and not len(parts):
            words += "; no deciding part is inconclusive: its parts' verdicts disagree"
        elif verdict == UNDECIDED:
            if len(planned):
                seeds, hours, runs, design = _decider(planned, costs)
                row.update(seeds_holds_at_2delta=seeds, cpu_hours_holds_at_2delta=hours, runs_holds_at_2delta=runs)
                words += f"; {design}"
            if row["unplanned"]:
                words += (f"; {row['unplanned']} inconclusive part(s) cannot be planned (fewer than 2 seeds carry "
                          "them)")
        row["line"] = words
        rows.append(row)
    return pd.DataFrame(rows, columns=CLAIM_SUMMARY_COLUMNS)


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
        hours = float(plan["cpu_hours_holds_at_2delta"].iloc[int(np.nanargmax(k.to_numpy(np.float64)))])
        most = f" with {int(np.nanmax(k))} seeds" + (f" ({hours:.3g} CPU-hours)" if np.isfinite(hours) else "")
    return f"{now} of {len(plan)} parts reach {TARGET:.0%} with this run's seeds if the effect is twice delta; {reach}{most}"
