"""Fig 4: ablations of receptor classes, collective sensing gates, muting, food layouts and patch number (SPEC 13).

Every panel reads the behaviour analysis's per-episode summary
(``analysis/behaviour/<assay>/episode_summary.parquet``: food_total, theil_t,
eod_probability, mean_nn_dist_cm, bites) and, where the analysis tests the
conditions, its Dunnett rows (``condition_tests.parquet``, one per group and
measure against the assay's first condition). Stars come from those rows; a
comparison the analysis does not test (patchy vs uniform, the N-patch trends)
is drawn without stars and its caption says so.
"""

from __future__ import annotations

import re
from collections.abc import Callable

import pandas as pd

from .panel import Panel, Tables
from .style import CONDITION_COLOURS, box_strip, condition_order, condition_palette, mean_lines, missing, stars_for

#: (y-axis label, short title) of each episode_summary measure.
MEASURES = {
    "food_total": ("food eaten per episode (pellets)", "Food"),
    "eod_probability": ("EOD probability per step", "EOD probability"),
    "mean_nn_dist_cm": ("nearest-neighbour distance (cm)", "Spacing"),
    "bites": ("bites per episode", "Bites"),
    "theil_t": ("Theil T of food", "Inequality"),
}
#: The N-patch assay's condition names: ``iso_<n>`` (fixed total food) and ``free_<n>`` (full food per patch).
NPATCH_CONDITION = re.compile(r"^(iso|free)_(\d+)$")


def dunnett_stars(tests: pd.DataFrame, measure: str, groups) -> dict:
    """Stars of each group's Dunnett row for ``measure`` (from condition_tests; ``n/a`` where there is none)."""
    return {g: stars_for(tests, group=g, measure=measure) for g in groups}


def ablation_label(condition: str) -> str:
    """Tick label of a receptor-ablation condition: the classes left on joined by '+' (M_A_K -> M+A+K)."""
    return condition.replace("_", "+")


def plain_label(condition: str) -> str:
    """Tick label of any other condition: underscores read as spaces (self_only -> self only)."""
    return str(condition).replace("_", " ")


def condition_box(assay: str, measure: str, title: str,
                  label: Callable[[str], str] = plain_label) -> Callable[[Tables, object], None]:
    """A draw function: ``measure`` per episode for each condition of ``assay``, Dunnett stars vs its control."""
    ylabel = MEASURES[measure][0]

    def draw(tables: Tables, ax) -> None:
        summary, tests = tables["summary"], tables["tests"]
        controls = tests["control"].dropna().unique() if "control" in tests else []
        control = controls[0] if len(controls) else None
        order = condition_order(assay, summary["condition"].dropna(), control)
        if not order:
            missing(ax, f"{assay} episode_summary has no condition")
            return
        control = order[0] if control is None else control  # no test row: the config's first, as the analysis
        others = [c for c in order if c != control]
        if box_strip(ax, summary, "condition", measure, order, condition_palette(order, control),
                     stars=dunnett_stars(tests, measure, others), labels={c: label(c) for c in order}):
            ax.set_xlabel("receptors on" if label is ablation_label else "condition")
            ax.set_ylabel(ylabel)
            ax.set_title(title)
            if len(order) > 4:
                ax.tick_params(axis="x", labelrotation=30)

    return draw


def layouts_box(measure: str, title: str) -> Callable[[Tables, object], None]:
    """A draw function: ``measure`` per episode in the patchy4 and the uniform4 assay side by side (no test)."""
    ylabel = MEASURES[measure][0]

    def draw(tables: Tables, ax) -> None:
        both = pd.concat([tables["patchy"].assign(layout="patchy"), tables["uniform"].assign(layout="uniform")],
                         ignore_index=True)
        order = ["patchy", "uniform"]
        if box_strip(ax, both, "layout", measure, order, condition_palette(order)):
            ax.set_xlabel("food layout (70 x 70 cm, 4 agents)")
            ax.set_ylabel(ylabel)
            ax.set_title(title)

    return draw


def npatch_frame(summary: pd.DataFrame) -> pd.DataFrame:
    """The N-patch episode summary with ``series`` (iso / free) and ``n_patches`` parsed from the condition."""
    parts = summary["condition"].astype(str).str.extract(NPATCH_CONDITION)
    if parts.isna().all(axis=None):
        raise ValueError(f"no npatch condition is named iso_<n> or free_<n>: {sorted(summary['condition'].unique())}")
    out = summary.assign(series=parts[0], n_patches=pd.to_numeric(parts[1]))
    return out.dropna(subset=["series"])


def npatch_food_ratio(tables: Tables, ax) -> None:
    """Panel M: each iso episode's food over the mean food of the free series at the same patch number."""
    frame = npatch_frame(tables["summary"])
    free_mean = frame[frame["series"] == "free"].groupby("n_patches")["food_total"].mean()
    iso = frame[frame["series"] == "iso"]
    denominator = iso["n_patches"].map(free_mean.where(free_mean > 0))  # a free series that ate nothing: no ratio
    ratio = iso.assign(food_ratio=iso["food_total"] / denominator, series="iso / free",
                       reason="the free series ate nothing at this patch number")
    if mean_lines(ax, ratio, "n_patches", "food_ratio", "series", {"iso / free": CONDITION_COLOURS[0]}):
        ax.axhline(1.0, color="black", lw=0.5, ls=":")
        ax.set_xlabel("number of patches")
        ax.set_ylabel("food, iso / mean free")
        ax.set_title("Food at fixed total vs full patches")


def npatch_theil(tables: Tables, ax) -> None:
    """Panel N: Theil T of food per episode against patch number, iso and free series."""
    frame = npatch_frame(tables["summary"])
    palette = dict(zip(["iso", "free"], CONDITION_COLOURS, strict=False))
    if mean_lines(ax, frame, "n_patches", "theil_t", "series", palette):
        ax.set_xlabel("number of patches")
        ax.set_ylabel(MEASURES["theil_t"][0])
        ax.set_title("Inequality vs patch number")
        ax.legend(title="food", loc="upper left", bbox_to_anchor=(1.0, 1.0))


def _summary(assay: str) -> dict[str, str]:
    return {"summary": f"analysis/behaviour/{assay}/episode_summary.parquet",
            "tests": f"analysis/behaviour/{assay}/condition_tests.parquet"}


def _caption(what: str, assay: str, measure: str) -> str:
    return (f"{what}: {measure} per episode (points; box = quartiles) in each condition of the {assay} assay, "
            f"from analysis/behaviour/{assay}/episode_summary; stars: Dunnett's test of each condition against "
            f"the assay's first (control) condition, read from condition_tests (measure {measure}).")


PANELS = [
    Panel("fig4", "A", condition_box("ablation1", "food_total", "Solo food", ablation_label), _summary("ablation1"),
          _caption("Receptor ablations, one agent", "ablation1", "food_total")),
    Panel("fig4", "B", condition_box("ablation4", "food_total", "Group food", ablation_label), _summary("ablation4"),
          _caption("Receptor ablations, four agents", "ablation4", "food_total")),
    Panel("fig4", "C", condition_box("ablation4", "eod_probability", "EOD probability", ablation_label),
          _summary("ablation4"), _caption("Receptor ablations, four agents (mean over agents)", "ablation4",
                                          "eod_probability")),
    Panel("fig4", "D", condition_box("ablation4", "mean_nn_dist_cm", "Spacing", ablation_label),
          _summary("ablation4"), _caption("Receptor ablations, four agents (mean over agents)", "ablation4",
                                          "mean_nn_dist_cm")),
    Panel("fig4", "E", condition_box("ablation4", "bites", "Bites", ablation_label), _summary("ablation4"),
          _caption("Receptor ablations, four agents (bites given, summed over agents)", "ablation4", "bites")),
    Panel("fig4", "F", condition_box("ablation4", "theil_t", "Inequality", ablation_label), _summary("ablation4"),
          _caption("Receptor ablations, four agents (Theil T of food over all agents)", "ablation4", "theil_t")),
    Panel("fig4", "G", condition_box("collective", "food_total", "Collective sensing: food"),
          _summary("collective"), _caption("Mormyromast image gates (self only: g_cons = 0; cons only: g_self = 0)",
                                           "collective", "food_total")),
    Panel("fig4", "H", condition_box("collective", "eod_probability", "Collective sensing: EOD"),
          _summary("collective"), _caption("Mormyromast image gates (self only: g_cons = 0; cons only: g_self = 0)",
                                           "collective", "eod_probability")),
    Panel("fig4", "I", condition_box("mute", "food_total", "Muting: group food"), _summary("mute"),
          _caption("Agent 0 of four muted vs none", "mute", "food_total")
          + " (Dunnett with one group; the paper's Mann-Whitney test is not in the analysis tables)."),
    Panel("fig4", "J", condition_box("mute", "mean_nn_dist_cm", "Muting: spacing"), _summary("mute"),
          _caption("Agent 0 of four muted vs none", "mute", "mean_nn_dist_cm")
          + " (Dunnett with one group; the paper's Mann-Whitney test is not in the analysis tables)."),
    Panel("fig4", "K", layouts_box("food_total", "Patchy vs uniform: food"),
          {"patchy": "analysis/behaviour/patchy4/episode_summary.parquet",
           "uniform": "analysis/behaviour/uniform4/episode_summary.parquet"},
          "Food eaten per episode by four agents in the patchy (patchy4) and the uniform (uniform4) 70 x 70 cm "
          "arena, from analysis/behaviour/<assay>/episode_summary. No stars: the patchy-vs-uniform Mann-Whitney "
          "test is not in any analysis table."),
    Panel("fig4", "L", layouts_box("theil_t", "Patchy vs uniform: inequality"),
          {"patchy": "analysis/behaviour/patchy4/episode_summary.parquet",
           "uniform": "analysis/behaviour/uniform4/episode_summary.parquet"},
          "Theil T of food over the four agents per episode in the patchy4 and uniform4 assays, from "
          "analysis/behaviour/<assay>/episode_summary. No stars: the patchy-vs-uniform Mann-Whitney test is not "
          "in any analysis table."),
    Panel("fig4", "M", npatch_food_ratio, {"summary": "analysis/behaviour/npatch/episode_summary.parquet"},
          "N-patch sweep (npatch assay): food of each iso episode (fixed total food, multiplier 1/n) over the mean "
          "food of the free series (full food per patch) at the same number of patches n; line: mean +- SEM, from "
          "analysis/behaviour/npatch/episode_summary. No trend test: the Spearman of the ratio against n is not in "
          "any analysis table."),
    Panel("fig4", "N", npatch_theil, {"summary": "analysis/behaviour/npatch/episode_summary.parquet"},
          "N-patch sweep (npatch assay): Theil T of food per episode against the number of patches, iso and free "
          "series; line: mean +- SEM, from analysis/behaviour/npatch/episode_summary. No trend test: the Spearman "
          "of Theil T against n is not in any analysis table."),
]
