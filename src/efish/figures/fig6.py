"""Fig 6: hidden-state dynamics: dimensionality, decoding, PLSC between agents and wideband power
(docs/methods/figures.md#panels).

Panels read the dynamics analysis (``analysis/dynamics/<assay>/``):
``dimensionality`` (D_eff, PCs for the variance fraction and wideband power
per agent-episode), ``subsampling`` (D_eff of random unit subsets),
``decoding`` and ``food_decoding`` (held-out decoding skill per target,
pooled over episodes), ``plsc`` (per distance bin), ``power_near_far`` and
the statistic tables ``size_tests`` (D_eff against N) and ``power_tests``
(near vs far, smaller vs larger), whose stars the panels draw. Where the
analysis does not yet write what a panel needs (the PCA variance spectrum),
the panel draws what there is and its caption, or the panel itself, says what
is missing.
"""

from __future__ import annotations

import numpy as np
import pandas as pd

from .. import layout
from ..config.schema import AnalysisConfig
from .panel import Panel, Tables
from .style import (
    FOOD_RANGE_COLOURS,
    NEUTRAL_COLOUR,
    RECEPTOR_COLOURS,
    analysis_settings,
    annotate_stars,
    assay_conditions,
    box_strip,
    condition_order,
    condition_palette,
    corner_note,
    group_size_colours,
    mean_lines,
    missing,
    size_class_colours,
    stars_for,
)

#: The dynamics analysis's Knollenorgan groups (efish.analysis.dynamics_tests.KNOLLENORGAN_GROUPS) as drawn.
KNOLLENORGAN_STATE = {"K": "K on", "noK": "K off"}
KNOLLENORGAN_COLOURS = {"K on": RECEPTOR_COLOURS["knollenorgan"], "K off": NEUTRAL_COLOUR}
KNOLLENORGAN_STYLES = {"K on": "-", "K off": "--"}
#: Readable names of the decoding targets (steps columns, efish.analysis.decoding.DECODE_TARGETS; a few older
#: targets too, so that the tables of earlier runs still draw with names). Distances are decoded as their log10
#: (efish.analysis.decoding.LOG_DISTANCES), and their names say so.
TARGET_LABELS = {
    "dist_agent_cm": "nearest agent: log distance", "bearing_agent_rad": "nearest agent: bearing",
    "dist_agent2_cm": "2nd agent: log distance", "size_agent1": "nearest agent: size",
    "size_agent2": "2nd agent: size", "n_knollen_agents": "agents heard (K)",
    "n_agents_100cm": "agents in K range (100 cm)",
    "dist_food_cm": "food: log distance", "bearing_food_rad": "food: bearing", "food_count_5cm": "pellets within 5 cm",
    "dist_wall_cm": "wall: log distance", "bearing_wall_rad": "wall: bearing", "size": "own size", "eod": "own EOD",
    "turn_rad": "turn", "log_morm_field": "log field (M, geometric)", "log_morm_sensed": "log reading (M, sensed)",
    "log_amp_field": "log field (A)", "knollen_spikes": "K inputs spiking", "err_knollen_rad": "error angle (K)",
    "err_morm_rad": "error angle (M)", "err_amp_rad": "error angle (A)",
}
#: Appended to the label of a readout target (a copy of the network's own input: its last action, size, sensor inputs).
READOUT_SUFFIX = " (readout)"
READOUT_HATCH = "////"
#: The decoding tables' column the bars draw (efish.analysis.decoding.summarise) and its axis label.
SKILL = "skill"
SKILL_LABEL = "held-out decoding skill"
POWER_LABEL = "wideband power (1/Hz)"


def dynamics_settings(tables: Tables, assay: str) -> AnalysisConfig:
    """The analysis settings the dynamics job of ``assay`` ran with (its ``analysis_settings.parquet``): thresholds
    named on a panel are those its tables were computed under, not the schema's defaults."""
    return analysis_settings(tables, "dynamics", assay)


def dimensionality_box(tables: Tables, ax) -> None:
    """Panel A: D_eff and the number of PCs reaching the variance fraction, per agent-episode of patchy4."""
    dims = tables["dims"]
    share = dynamics_settings(tables, "patchy4").variance_fraction
    names = {"d_eff": "D_eff", "pcs_for_variance": f"PCs for {share:.0%} var."}
    long = dims.melt(id_vars=[c for c in dims.columns if c not in names], value_vars=list(names),
                     var_name="measure", value_name="dimensions")
    order = list(names)
    if box_strip(ax, long, "measure", "dimensions", order, condition_palette(order), labels=names):
        ax.set_xlabel("per agent-episode (patchy4)")
        ax.set_ylabel("dimensions of the hidden state")
        ax.set_title("Hidden-state dimensionality")


def groupsize_frame(table: pd.DataFrame, tables: Tables) -> pd.DataFrame:
    """A groupsize table with ``n_agents`` and ``knollenorgans`` (K on / K off) from the config each condition
    recorded (the panel's conditions/groupsize table), whatever the conditions are called."""
    # imported here: the workflow imports every figure module to list the panels, and this one pulls in sklearn
    from ..analysis.dynamics_tests import groupsize_parts

    frame = groupsize_parts(table, assay_conditions(tables, "groupsize"))
    return frame.assign(knollenorgans=frame["knollenorgans"].map(KNOLLENORGAN_STATE))


def deff_vs_group_size(tables: Tables, ax) -> None:
    """Panel B: D_eff per agent-episode against group size, Knollenorgans on and off (mean +- SEM)."""
    frame = groupsize_frame(tables["dims"], tables)
    if mean_lines(ax, frame, "n_agents", "d_eff", "knollenorgans", KNOLLENORGAN_COLOURS, KNOLLENORGAN_STYLES):
        # the dynamics analysis's Spearman of D_eff against N per Knollenorgan state (size_tests; group K / noK)
        tests = tables["tests"]
        notes = []
        for key, state in KNOLLENORGAN_STATE.items():
            row = tests[tests["group"] == key]
            rho = float(row["effect"].iloc[0]) if len(row) else np.nan
            notes.append(f"{state}: " + (f"rho {rho:+.2f} " if np.isfinite(rho) else "") + stars_for(row))
        corner_note(ax, "\n".join(notes))
        ax.set_xlabel("group size N (agents)")
        ax.set_ylabel("D_eff of the hidden state")
        ax.set_title("Dimensionality vs group size")
        ax.legend(loc="upper center")  # the room corner_note made above the points


def subsampling_curves(tables: Tables, ax) -> None:
    """Panel C: mean D_eff of random unit subsets against the fraction of units kept, per group size and K."""
    frame = groupsize_frame(tables["subsampling"], tables).dropna(subset=["d_eff"])
    if frame.empty:
        missing(ax, "no finite D_eff in the groupsize subsampling table")
        return
    means = frame.groupby(["n_agents", "knollenorgans", "fraction"])["d_eff"].mean().reset_index()
    colours = group_size_colours(means["n_agents"])
    for (n, k), sub in means.groupby(["n_agents", "knollenorgans"]):
        ax.plot(sub["fraction"], sub["d_eff"], color=colours[int(n)], ls=KNOLLENORGAN_STYLES[k], marker="o", ms=2.5,
                label=f"N = {int(n)}" if k == "K on" else None)
    ax.plot([], [], color=NEUTRAL_COLOUR, ls=KNOLLENORGAN_STYLES["K off"], label="K off")
    ax.set_xlabel("fraction of hidden units kept")
    ax.set_ylabel("D_eff (mean over draws)")
    ax.set_title("Unit subsampling")
    ax.legend(loc="upper left", fontsize=6, ncols=1)


def readout_rows(decoding: pd.DataFrame) -> pd.Series:
    """Which rows of a decoding table are readouts of the network's own input (docs/claims/index.md#rule-7): its
    ``readout`` column, or, in a table written before that column existed, membership of
    efish.analysis.decoding.READOUT_TARGETS."""
    if "readout" in decoding.columns:
        return decoding["readout"].fillna(False).astype(bool)
    # imported here: the workflow imports every figure module to list the panels, and the analysis is heavier
    from ..analysis.decoding import READOUT_TARGETS

    return decoding["target"].isin(list(READOUT_TARGETS))


def decoding_bars(assay: str, title: str, control: str | None = None):
    """A draw function: held-out decoding skill per target (pooled over episodes, the dynamics decoding table), one
    bar colour per condition (``control``, default the assay's first condition, grey).

    The sensed targets are ranked, best on top, as claim C19 ranks them; the
    readouts (copies of the network's input: its last turn and EOD, its own
    size, summaries of its sensor inputs) are not ranked among them: they
    follow below a dashed line, hatched, labelled "(readout)".
    """
    def draw(tables: Tables, ax) -> None:
        import seaborn as sns

        decoding = tables["decoding"]
        scored = decoding[np.isfinite(pd.to_numeric(decoding[SKILL], errors="coerce"))]
        if scored.empty:
            reasons = [r for r in decoding["reason"].astype(str) if r and r != "nan"]
            missing(ax, f"no decoding skill in {assay}: {reasons[0] if reasons else 'empty table'}")
            return
        readout = readout_rows(scored)
        scored = scored.assign(label=scored["target"].map(lambda t: TARGET_LABELS.get(t, t))
                               + np.where(readout, READOUT_SUFFIX, ""))

        def ranked(rows: pd.DataFrame) -> list[str]:
            return rows.groupby("label")[SKILL].mean().sort_values(ascending=False).index.tolist()

        sensed, readouts = ranked(scored[~readout]), ranked(scored[readout])
        conditions = condition_order(tables, assay, scored["condition"], control)
        sns.barplot(data=scored, x=SKILL, y="label", hue="condition", order=sensed + readouts,
                    hue_order=conditions, palette=condition_palette(conditions, control), orient="h",
                    legend=len(conditions) > 1, ax=ax)
        for bar in ax.patches:  # bars sit at y = their label's index in the order
            if bar.get_height() > 0 and round(bar.get_y() + bar.get_height() / 2) >= len(sensed):
                bar.set_hatch(READOUT_HATCH)
                bar.set_alpha(0.5)
        if sensed and readouts:
            ax.axhline(len(sensed) - 0.5, color=NEUTRAL_COLOUR, lw=0.5, ls="--")
        ax.axvline(0.0, color="black", lw=0.5)
        ax.set_xlabel(SKILL_LABEL)
        ax.set_ylabel("decoded variable")
        ax.tick_params(axis="y", labelsize=6)
        ax.set_title(title)
        if len(conditions) > 1:
            ax.legend(loc="best", fontsize=6)

    return draw


def food_decoding_bars(tables: Tables, ax) -> None:
    """Panel F: decoding skill of the food variables with the nearest food in receptor range (near) and beyond it
    (far), one bar pair per variable, from the dynamics food_decoding table of wide2 (conditions pooled by mean)."""
    import seaborn as sns

    table = tables["food_decoding"]
    scored = table[np.isfinite(pd.to_numeric(table.get(SKILL, pd.Series(dtype=float)), errors="coerce"))]
    if scored.empty:
        reasons = [r for r in table.get("reason", pd.Series(dtype=str)).astype(str) if r and r != "nan"]
        missing(ax, f"no food decoding skill in wide2: {reasons[0] if reasons else 'empty table'}")
        return
    scored = scored.assign(label=scored["target"].map(lambda t: TARGET_LABELS.get(t, t)))
    ranges = [r for r in FOOD_RANGE_COLOURS if r in set(scored["food"])]
    sns.barplot(data=scored, x=SKILL, y="label", hue="food", hue_order=ranges, palette=FOOD_RANGE_COLOURS,
                orient="h", errorbar=None, ax=ax)
    ax.axvline(0.0, color="black", lw=0.5)
    near = dynamics_settings(tables, "wide2").claims_food_near_cm
    ax.legend(title=f"food (near: <= {near:g} cm)", fontsize=6, title_fontsize=6, loc="best")
    ax.set_xlabel(SKILL_LABEL)
    ax.set_ylabel("decoded variable")
    ax.set_title("Two agents: food near vs far")


def bin_label(lo: float, hi: float) -> str:
    """Tick label of a PLSC distance bin (lo, hi] in cm."""
    if lo <= 0:
        return f"<= {hi:g}"
    return f"> {lo:g}" if not np.isfinite(hi) else f"{lo:g}-{hi:g}"


def plsc_bars(column: str, ylabel: str, title: str, integer: bool = False):
    """A draw function: one PLSC value per pair-distance bin of wide2 (agents 0 and 1); an empty bin says why.

    ``integer`` puts the y ticks on whole numbers (counts of dimensions)."""
    def draw(tables: Tables, ax) -> None:
        plsc = tables["plsc"]
        if "lo_cm" not in plsc or plsc["lo_cm"].isna().all():
            missing(ax, f"plsc table has no distance bins: {plsc['reason'].iloc[0] if len(plsc) else 'empty'}")
            return
        conditions = condition_order(tables, "wide2", plsc["condition"].dropna())
        palette = condition_palette(conditions)
        bins = plsc[["lo_cm", "hi_cm"]].drop_duplicates().sort_values("lo_cm").to_numpy()
        width = 0.8 / len(conditions)
        for j, cond in enumerate(conditions):
            rows = plsc[plsc["condition"] == cond].set_index(["lo_cm", "hi_cm"])
            for i, (lo, hi) in enumerate(bins):
                x = i + (j - (len(conditions) - 1) / 2) * width
                row = rows.loc[(lo, hi)] if (lo, hi) in rows.index else None
                value = float(row[column]) if row is not None else np.nan
                if np.isfinite(value):  # the value on the bar, so that a zero is seen as a zero
                    ax.bar(x, value, width * 0.9, color=palette[cond], label=cond if i == 0 else None)
                    ax.text(x, value, f"{value:.3g}", ha="center", va="bottom", fontsize=6)
                else:  # a bin with too few steps: say so where its bar would be
                    ax.text(x, 0.02, "n/a", ha="center", va="bottom", fontsize=6, color=NEUTRAL_COLOUR,
                            transform=ax.get_xaxis_transform())
        ax.set_xticks(range(len(bins)), [bin_label(lo, hi) for lo, hi in bins])
        ax.set_xlim(-0.6, len(bins) - 0.4)
        if integer:
            from matplotlib.ticker import MaxNLocator

            ax.yaxis.set_major_locator(MaxNLocator(integer=True))
        ax.set_xlabel("distance between the two agents (cm)")
        ax.set_ylabel(ylabel)
        ax.set_title(title)
        if len(conditions) > 1:
            ax.legend(loc="best")

    return draw


def _pair_bracket(ax, frame: pd.DataFrame, y: str, tests: pd.DataFrame, measure: str) -> None:
    """A bracket over the two boxes with the stars of the ``measure`` row of a dynamics statistic table."""
    top = float(np.nanmax(pd.to_numeric(frame[y], errors="coerce")))
    row = tests[tests["measure"] == measure] if "measure" in tests.columns else tests.iloc[:0]
    annotate_stars(ax, 0, top * 1.08, stars_for(row), x2=1)
    ax.set_ylim(top=top * 1.3)


def _power_scaled(frame: pd.DataFrame) -> tuple[pd.DataFrame, str]:
    """``wideband_power`` in units of a power of ten that brings its largest value to 1-10, and the axis label
    naming the unit: matplotlib's offset text (``1e-3``) would sit on the title."""
    values = pd.to_numeric(frame["wideband_power"], errors="coerce").to_numpy(float)
    top = np.nanmax(values) if np.isfinite(values).any() else np.nan
    exponent = int(np.floor(np.log10(top))) if np.isfinite(top) and top > 0 else 0
    if exponent == 0:
        return frame, POWER_LABEL
    return frame.assign(wideband_power=values / 10.0 ** exponent), f"wideband power (10$^{{{exponent}}}$ / Hz)"


def power_near_far(tables: Tables, ax) -> None:
    """Panel I: wideband power of each agent-episode over its steps with the conspecific near vs far, pairs joined,
    with the Wilcoxon stars of power_tests."""
    (frame, label), order = _power_scaled(tables["power"]), ["near", "far"]
    if not box_strip(ax, frame, "where", "wideband_power", order, condition_palette(order)):
        return
    wide = frame.pivot_table(index=["condition", "episode", "agent"], columns="where", values="wideband_power")
    wide = wide.reindex(columns=order).dropna()
    ax.plot([0, 1], wide.to_numpy(float).T, color=NEUTRAL_COLOUR, lw=0.3, alpha=0.5, zorder=1)
    _pair_bracket(ax, frame, "wideband_power", tables["tests"], "near_far")
    a = dynamics_settings(tables, "wide2")
    ax.set_xticks([0, 1], [f"near (<= {a.claims_near_cm:g} cm)", f"far (> {a.claims_far_cm:g} cm)"])
    ax.set_xlabel("nearest conspecific (wide2)")
    ax.set_ylabel(label)
    ax.set_title("Power vs conspecific distance")


def power_by_size(tables: Tables, ax) -> None:
    """Panel J: wideband power of the smallest agent of each episode vs the others (equal sizes dropped), with the
    Mann-Whitney stars of power_tests."""
    # imported here: the workflow imports every figure module to list the panels, and this one pulls in sklearn
    from ..analysis.dynamics_tests import smaller_larger

    frame, label = _power_scaled(smaller_larger(tables["dims"], tables["episodes"]))
    order = ["smaller", "larger"]
    if box_strip(ax, frame, "role", "wideband_power", order, dict(zip(order, size_class_colours(2), strict=True))):
        _pair_bracket(ax, frame, "wideband_power", tables["tests"], "size")
        ax.set_xlabel("agent within its episode (wide2)")
        ax.set_ylabel(label)
        ax.set_title("Power vs size")


def _dyn(assay: str, table: str) -> str:
    return layout.analysis_table("dynamics", assay, table)


PANELS = [
    Panel("fig6", "A", dimensionality_box, {"dims": _dyn("patchy4", "dimensionality")},
          "Dimensionality of the hidden state per agent-episode of the patchy4 assay: D_eff (1 / sum of squared "
          "normalised PCA variances) and the number of PCs reaching analysis.variance_fraction of the variance, "
          "from analysis/dynamics/patchy4/dimensionality. The cumulative-variance curve itself needs the PCA "
          "variance spectrum, which no analysis table holds yet."),
    Panel("fig6", "B", deff_vs_group_size, {"dims": _dyn("groupsize", "dimensionality"),
                                            "tests": _dyn("groupsize", "size_tests")},
          "D_eff of the hidden state per agent-episode against group size N, Knollenorgans on (solid) and off "
          "(dashed), mean +- SEM, groupsize assay, analysis/dynamics/groupsize/dimensionality; rho and stars: "
          "Spearman of D_eff against N over agent-episodes per Knollenorgan state (dynamics size_tests)."),
    Panel("fig6", "C", subsampling_curves, {"subsampling": _dyn("groupsize", "subsampling")},
          "D_eff of random subsets of hidden units (analysis.subsample_fractions of the units, "
          "analysis.subsample_draws draws each) against the fraction kept, mean over draws and agent-episodes, per "
          "group size (colour) and Knollenorgan state (dashed: off), groupsize assay, "
          "analysis/dynamics/groupsize/subsampling."),
    Panel("fig6", "D", decoding_bars("homing", "Homing: decoding", control="raycast"), {"decoding": _dyn("homing", "decoding")},
          "Linear decoding of step variables from the homer's hidden state, electric and ray-casting homing "
          "policies: held-out skill (1 - SSE of the readout / SSE of the training mean, on each episode held out "
          "whole by analysis.decode_folds-fold cross-validation), pooled over episodes, analysis/dynamics/homing/decoding (per episode: "
          "decoding_episodes, which claim C18 tests); targets without a skill (e.g. no food in the arena) are left "
          "out. Readouts of the network's own input (its last turn and EOD, its size, its Knollenorgan inputs "
          "spiking, its largest Mormyromast input) are drawn hatched below the dashed line, not ranked."),
    Panel("fig6", "E", decoding_bars("wide2", "Two agents: decoding"), {"decoding": _dyn("wide2", "decoding")},
          "Held-out decoding skill per step variable from the hidden state of both agents of the wide2 assay "
          "(160 x 40 cm), pooled over episodes, analysis/dynamics/wide2/decoding. Each state is decoded against the "
          "world it has observed (the step's observation it has taken in). The sensed variables are ranked best "
          "first, as claim C19 ranks them; the readouts of the network's own input (its last turn and EOD, its own "
          "size, its Knollenorgan inputs spiking and its largest Mormyromast input) are drawn hatched below the "
          "dashed line and not ranked. Targets without a skill are left out."),
    Panel("fig6", "F", food_decoding_bars, {"food_decoding": _dyn("wide2", "food_decoding")},
          "Held-out decoding skill of the food variables (distance and bearing of the nearest pellet) from the "
          "hidden states of the wide2 agents on the steps with that pellet within analysis.claims_food_near_cm "
          "(near, in receptor range) and beyond it (far), pooled over episodes; "
          "analysis/dynamics/wide2/food_decoding. Claim C19 tests near > far on its episodes."),
    Panel("fig6", "G", plsc_bars("s_1", "first PLSC singular value", "PLSC: first component"),
          {"plsc": _dyn("wide2", "plsc")},
          "Partial least squares correlation of the two wide2 agents' z-scored hidden states per pair-distance bin "
          "(analysis.plsc_edges_cm): the first singular value of their cross-covariance, "
          "analysis/dynamics/wide2/plsc. The first component's score correlation and its Spearman against "
          "distance are not in the table yet."),
    Panel("fig6", "H", plsc_bars("n_significant", "significant PLSC dimensions", "PLSC: shared dimensions", integer=True),
          {"plsc": _dyn("wide2", "plsc")},
          "Number of PLSC components whose singular value and score correlation both exceed the "
          "analysis.plsc_percentile of a circular-shift null (counted until the first failure), per pair-distance "
          "bin of the wide2 assay, analysis/dynamics/wide2/plsc."),
    Panel("fig6", "I", power_near_far, {"power": _dyn("wide2", "power_near_far"), "tests": _dyn("wide2", "power_tests")},
          "Wideband power of the hidden state (spectrogram, analysis.spectrogram_window-step windows) of each "
          "agent-episode of the wide2 assay over its steps with the nearest conspecific within analysis."
          "claims_near_cm vs beyond analysis.claims_far_cm, pairs joined (dynamics power_near_far); stars: Wilcoxon "
          "signed-rank far vs near over agent-episodes (dynamics power_tests, measure near_far)."),
    Panel("fig6", "J", power_by_size, {"dims": _dyn("wide2", "dimensionality"),
                                       "episodes": layout.assay_table("wide2", "episodes"),
                                       "tests": _dyn("wide2", "power_tests")},
          "Wideband power of the hidden state per agent-episode of the wide2 assay, the smallest agent of each "
          "episode vs the others (sizes from the episodes table; episodes of equal sizes left out), "
          "analysis/dynamics/wide2/dimensionality; stars: Mann-Whitney smaller vs larger (dynamics power_tests, "
          "measure size)."),
]
