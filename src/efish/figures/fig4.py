"""Fig 4: ablations of receptor classes, collective sensing gates, muting, food layouts and patch number
(docs/methods/figures.md#panels).

Every panel reads the behaviour analysis's per-episode summary
(``analysis/behaviour/<assay>/episode_summary.parquet``: food_total, theil_t,
eod_probability, mean_nn_dist_cm, bites) and, where the analysis tests the
conditions, its Dunnett rows (``condition_tests.parquet``, one per group and
measure against the assay's first condition). Stars come from those rows; a
comparison the analysis does not test (patchy vs uniform, the N-patch trends,
the mute assay's 4-agent set) is drawn without stars (``n/a``) and its caption
says so.
"""

from __future__ import annotations

import re
from collections.abc import Callable, Mapping

import pandas as pd

from .. import layout
from ..config.schema import EfishConfig
from .panel import Panel, Tables
from .style import (
    CONDITION_COLOURS,
    CONTROL_COLOUR,
    annotate_stars,
    assay_conditions,
    box_strip,
    condition_order,
    condition_palette,
    finite,
    mean_lines,
    missing,
    stars_for,
    tint,
)

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
#: Tick labels of the collective assay's conditions (config/assay/collective.yaml); others read as plain_label.
COLLECTIVE_LABELS = {"self_only": "self only\n(clean gate)", "self_only_authors": "self only\n(authors' mode)",
                     "cons_only": "cons only"}
#: Collective conditions drawn in a light tint of another's colour: the authors' self-only mode of the clean gate.
COLLECTIVE_VARIANTS = {"self_only_authors": "self_only"}
#: The mute assay's two designs (config/assay/mute.yaml): (unmuted, muted condition, which design it is). The
#: first is the Results' (2 agents, uniform; the authors' code runs it) and decides claim C12; the second is the
#: Methods' (4 agents, patchy), drawn beside it.
MUTE_DESIGNS = (("intact", "muted", "Results, decides C12"), ("intact4", "muted4", "Methods"))


def dunnett_stars(tests: pd.DataFrame, measure: str, groups) -> dict:
    """Stars of each group's Dunnett row for ``measure`` (from condition_tests; ``n/a`` where there is none)."""
    return {g: stars_for(tests, group=g, measure=measure) for g in groups}


def ablation_label(condition: str) -> str:
    """Tick label of a receptor-ablation condition: the classes left on joined by '+' (M_A_K -> M+A+K)."""
    return condition.replace("_", "+")


def plain_label(condition: str) -> str:
    """Tick label of any other condition: underscores read as spaces (self_only -> self only)."""
    return str(condition).replace("_", " ")


def collective_label(condition: str) -> str:
    """Tick label of a collective-sensing condition (:data:`COLLECTIVE_LABELS`, else :func:`plain_label`)."""
    return COLLECTIVE_LABELS.get(condition, plain_label(condition))


def condition_box(assay: str, measure: str, title: str, label: Callable[[str], str] = plain_label,
                  variants: dict[str, str] | None = None) -> Callable[[Tables, object], None]:
    """A draw function: ``measure`` per episode for each condition of ``assay``, Dunnett stars vs its control.

    ``variants`` maps a condition to another whose colour it takes, lighter (a variant of the same treatment).
    """
    ylabel = MEASURES[measure][0]

    def draw(tables: Tables, ax) -> None:
        summary, tests = tables["summary"], tables["tests"]
        controls = tests["control"].dropna().unique() if "control" in tests else []
        control = controls[0] if len(controls) else None
        order = condition_order(tables, assay, summary["condition"].dropna(), control)
        if not order:
            missing(ax, f"{assay} episode_summary has no condition")
            return
        control = order[0] if control is None else control  # no test row: the assay's first, as the analysis
        others = [c for c in order if c != control]
        palette = condition_palette(order, control)
        palette |= {c: tint(palette[base]) for c, base in (variants or {}).items() if c in palette and base in palette}
        if box_strip(ax, summary, "condition", measure, order, palette,
                     stars=dunnett_stars(tests, measure, others), labels={c: label(c) for c in order}):
            ax.set_xlabel("receptors on" if label is ablation_label else "condition")
            ax.set_ylabel(ylabel)
            ax.set_title(title)
            if len(order) > 4:
                ax.tick_params(axis="x", labelrotation=30)

    return draw


def mute_design_labels(configs: Mapping[str, EfishConfig]) -> tuple[list[str], dict[str, str]]:
    """The x-axis label of each mute design (:data:`MUTE_DESIGNS`) and the tick label of each of its conditions,
    from the mute assay's recorded conditions ``configs`` (agents, food layout, arena size, who is muted)."""

    def muted(cond: str) -> str:
        ids = configs[cond].env.muted
        return f"agent{'s' if len(ids) > 1 else ''} {', '.join(map(str, ids))}\nmuted" if ids else "none\nmuted"

    groups = []
    for intact, _, which in MUTE_DESIGNS:
        cfg = configs[intact]
        groups.append(f"{cfg.env.n_agents} agents, {cfg.arena.layout} {cfg.arena.width_cm:g}x{cfg.arena.height_cm:g}"
                      f"\n({which})")
    return groups, {c: muted(c) for intact, treated, _ in MUTE_DESIGNS for c in (intact, treated)}


def mute_box(measure: str, title: str) -> Callable[[Tables, object], None]:
    """A draw function: ``measure`` per episode in the mute assay, the two designs side by side (the Results' first),
    each muted vs intact with the stars of a condition_tests row of exactly that pair (``n/a`` when none)."""
    ylabel = MEASURES[measure][0]

    def draw(tables: Tables, ax) -> None:
        summary, tests = tables["summary"], tables["tests"]
        order: list[str] = []
        for intact, treated, _ in MUTE_DESIGNS:
            order += [*([""] if order else []), intact, treated]
        if not set(order) & set(summary["condition"].dropna()):
            missing(ax, f"mute episode_summary has none of the conditions {', '.join(c for c in order if c)}")
            return
        palette = {"": CONTROL_COLOUR, **{c: colour for intact, treated, _ in MUTE_DESIGNS
                                          for c, colour in ((intact, CONTROL_COLOUR), (treated, CONDITION_COLOURS[0]))}}
        groups, labels = mute_design_labels(assay_conditions(tables, "mute"))
        if not box_strip(ax, summary, "condition", measure, order, palette, labels=labels):
            return
        values = finite(summary.loc[summary["condition"].isin(order), measure])
        lo, hi = float(values.min()), float(values.max())
        pad = (hi - lo) * 0.06 or max(abs(hi), 1.0) * 0.06
        for intact, treated, _ in MUTE_DESIGNS:
            i = order.index(intact)
            top = finite(summary.loc[summary["condition"].isin([intact, treated]), measure])
            annotate_stars(ax, i, (top.max() if top.size else hi) + pad,
                           stars_for(tests, group=treated, control=intact, measure=measure), x2=i + 1)
        ax.set_ylim(top=hi + 4 * pad)
        # the design of each pair on a second row of x labels
        ax.set_xticks([order.index(intact) + 0.5 for intact, _, _ in MUTE_DESIGNS], groups, minor=True)
        ax.tick_params(axis="x", which="minor", length=0, pad=22)  # below the two-line condition labels
        ax.set_xlabel("muting design")
        ax.set_ylabel(ylabel)
        ax.set_title(title)

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


def _episode_summary(assay: str) -> str:
    return layout.analysis_table("behaviour", assay, "episode_summary")


def _summary(assay: str) -> dict[str, str]:
    return {"summary": _episode_summary(assay), "tests": layout.analysis_table("behaviour", assay, "condition_tests")}


def _caption(what: str, assay: str, measure: str) -> str:
    return (f"{what}: {measure} per episode (points; box = quartiles) in each condition of the {assay} assay, "
            f"from analysis/behaviour/{assay}/episode_summary; stars: Dunnett's test of each condition against "
            f"the assay's first (control) condition, read from condition_tests (measure {measure}).")


_COLLECTIVE = ("Mormyromast image gates (self only, clean gate: g_cons = 0, the own EOD's wall images removed; self "
               "only, authors' mode: g_cons = 0 with the own EOD's wall images left in the reading, "
               "sensors.mormyromast.wall_distortion on, as the authors' code reads it; cons only: g_self = 0)")


def _mute_caption(measure: str) -> str:
    return (f"Muting: {measure} per episode (points; box = quartiles) in the mute assay, from "
            "analysis/behaviour/mute/episode_summary, in two designs side by side. Left, the Results' design, which "
            "decides claim C12 (the one the authors' code runs): 2 agents in the uniform 70 x 70 cm arena, agent 1 "
            "muted (muted) vs none (intact). Right, the Methods' design: 4 agents in the patchy 70 x 70 cm arena, "
            "agent 0 muted (muted4) vs none (intact4). The conditions of a design share their episode seeds. Stars: "
            "the condition_tests row of exactly that pair (measure " + measure + "); the behaviour analysis's "
            "Dunnett rows test every condition against the assay's first (intact), so the 2-agent pair's stars are "
            "Dunnett-adjusted over the assay's other conditions and the 4-agent pair has no row of its own (n/a); "
            "the paired tests of claim C12 are in the claims table.")


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
    Panel("fig4", "G", condition_box("collective", "food_total", "Collective sensing: food", collective_label,
                                     COLLECTIVE_VARIANTS),
          _summary("collective"), _caption(_COLLECTIVE, "collective", "food_total")),
    Panel("fig4", "H", condition_box("collective", "eod_probability", "Collective sensing: EOD", collective_label,
                                     COLLECTIVE_VARIANTS),
          _summary("collective"), _caption(_COLLECTIVE, "collective", "eod_probability")),
    Panel("fig4", "I", mute_box("food_total", "Muting: group food"), _summary("mute"), _mute_caption("food_total")),
    Panel("fig4", "J", mute_box("mean_nn_dist_cm", "Muting: spacing"), _summary("mute"),
          _mute_caption("mean_nn_dist_cm")),
    Panel("fig4", "K", layouts_box("food_total", "Patchy vs uniform: food"),
          {"patchy": _episode_summary("patchy4"), "uniform": _episode_summary("uniform4")},
          "Food eaten per episode by four agents in the patchy (patchy4) and the uniform (uniform4) 70 x 70 cm "
          "arena, from analysis/behaviour/<assay>/episode_summary. No stars: the patchy-vs-uniform Mann-Whitney "
          "test is not in any analysis table."),
    Panel("fig4", "L", layouts_box("theil_t", "Patchy vs uniform: inequality"),
          {"patchy": _episode_summary("patchy4"), "uniform": _episode_summary("uniform4")},
          "Theil T of food over the four agents per episode in the patchy4 and uniform4 assays, from "
          "analysis/behaviour/<assay>/episode_summary. No stars: the patchy-vs-uniform Mann-Whitney test is not "
          "in any analysis table."),
    Panel("fig4", "M", npatch_food_ratio, {"summary": _episode_summary("npatch")},
          "N-patch sweep (npatch assay): food of each iso episode (fixed total food, multiplier 1/n) over the mean "
          "food of the free series (full food per patch) at the same number of patches n; line: mean +- SEM, from "
          "analysis/behaviour/npatch/episode_summary. No trend test: the Spearman of the ratio against n is not in "
          "any analysis table."),
    Panel("fig4", "N", npatch_theil, {"summary": _episode_summary("npatch")},
          "N-patch sweep (npatch assay): Theil T of food per episode against the number of patches, iso and free "
          "series; line: mean +- SEM, from analysis/behaviour/npatch/episode_summary. No trend test: the Spearman "
          "of Theil T against n is not in any analysis table."),
]
