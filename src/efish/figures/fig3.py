"""Fig 3: signalling and foraging of the selected seed (docs/methods/figures.md#panels), plus the supplement's IDI
histogram.

Assays (docs/methods/assays.md): the two-agent wide arena ``wide2`` for the signalling panels
C-J, the four-agent patchy arena ``patchy4`` for the ethogram, trajectories
and the size panels (A, B, K-P). Every panel reads analysis tables (or, for
the trajectories, the rollout tables) and takes its tests from the analyses'
statistic tables; nothing here fits or tests anything. The arena and the frame
rate come from the conditions the run recorded (``conditions/<assay>``). The assays have one
condition each (the selected seed's behaviour, drawn in SELECTED_COLOUR);
should one have several, each is drawn in its own colour.
"""

from __future__ import annotations

import textwrap

import numpy as np
import pandas as pd

from .. import layout
from ..config.schema import EfishConfig
from .panel import Panel
from .style import (
    CONDITION_COLOURS,
    HEATMAP_CMAP,
    NEUTRAL_COLOUR,
    SELECTED_COLOUR,
    agent_colour,
    assay_conditions,
    condition_palette,
    corner_note,
    missing,
    stars_for,
)

SIGNALLING, FORAGING = "wide2", "patchy4"
#: What the EOD-rate-vs-distance panels E-G measure to, per ``to`` of the rate_by_distance table.
DISTANCE_LABELS = {"agent": "nearest agent", "food": "nearest food", "wall": "nearest wall"}
#: Peri-event panels: the ``event`` of the peri_event table and the words on the time axis.
EVENT_LABELS = {"ate": "eating", "bit": "biting", "was_bitten": "being bitten"}
SOURCE_LABELS = {"agents": "agents", "real_fish": "real fish"}
REAL_FISH_COLOUR = "black"
#: The supplement's IDI histogram draws both assays' agents: the signalling assay in the selected-seed colour.
ASSAY_COLOURS = {FORAGING: CONDITION_COLOURS[0], SIGNALLING: SELECTED_COLOUR}


# ----------------------------------------------------------------- helpers
def _why(table: pd.DataFrame, default: str) -> str:
    """The first non-empty ``reason`` of ``table`` (why its rows are NaN), else ``default``."""
    reasons = [r for r in table.get("reason", pd.Series(dtype=str)).dropna().astype(str) if r]
    return reasons[0] if reasons else default


def _missing(ax, why: str) -> None:
    """:func:`missing` with the reason wrapped to the panel's width (one column, 3.5 in)."""
    missing(ax, textwrap.fill(why, 42))


def _log_axes(ax, which: str = "xy") -> None:
    """Log scales. Intervals (x) are labelled in plain ms at 1, 2, 5 x 10^k, which stays readable over the
    one or two decades IDIs span; probabilities and densities (y) at the decades. Minor labels (2x10^1 ...)
    would collide at print size."""
    from matplotlib.ticker import FuncFormatter, LogLocator, NullFormatter

    for name in which:
        getattr(ax, f"set_{name}scale")("log")
        axis = getattr(ax, f"{name}axis")
        axis.set_minor_formatter(NullFormatter())
        if name == "x":
            axis.set_major_locator(LogLocator(subs=(1.0, 2.0, 5.0)))
            axis.set_major_formatter(FuncFormatter(lambda v, _: f"{v:g}"))


def _rows(ax, table: pd.DataFrame, columns: list[str], what: str) -> pd.DataFrame | None:
    """The rows of ``table`` whose ``columns`` are all finite; none: say why on the panel and return None."""
    if not set(columns) <= set(table.columns):
        _missing(ax, f"{what} lacks columns {sorted(set(columns) - set(table.columns))}")
        return None
    rows = table[np.isfinite(table[columns].astype(float)).all(axis=1)]
    if rows.empty:
        _missing(ax, f"{what}: {_why(table, 'no finite rows')}")
        return None
    return rows


def _colours(conditions) -> dict:
    """One condition (the selected seed): SELECTED_COLOUR; several: the shared condition palette."""
    conditions = sorted(set(conditions))
    return {conditions[0]: SELECTED_COLOUR} if len(conditions) == 1 else condition_palette(conditions)


def _stat_text(stats: pd.DataFrame, symbol: str, **where) -> str:
    """``symbol = effect, p = ..  stars`` of the statistic row matching ``where``, or why there is none."""
    rows = stats
    for column, value in where.items():
        rows = rows[rows[column] == value] if column in rows else rows.iloc[:0]
    if rows.empty:
        return "no test in the statistic table"
    row = rows.iloc[0]
    if not np.isfinite(row["effect"]):
        return f"test n/a: {row['reason']}"
    p = "p < 0.0001" if row["p"] < 1e-4 else f"p = {row['p']:.2g}"  # scipy returns p = 0 for a perfect rank match
    return f"{symbol} = {row['effect']:.2f}, {p} {stars_for(rows, **where)} (n = {int(row['n'])})"


def _condition_config(tables: dict[str, pd.DataFrame], assay: str, condition) -> EfishConfig:
    """The config the run recorded for ``condition`` of ``assay`` (its arena, its frame rate)."""
    configs = assay_conditions(tables, assay)
    if condition not in configs:
        raise ValueError(f"condition {condition!r} of assay {assay} is not in its conditions table "
                         f"({layout.assay_table(assay, 'conditions')} holds {', '.join(configs)}): rerun the assay")
    return configs[condition]


def _analysis(analysis: str, assay: str, table: str) -> str:
    return layout.analysis_table(analysis, assay, table)


# ------------------------------------------------------------ A, B: patchy4
def ethogram(tables: dict[str, pd.DataFrame], ax) -> None:
    """Panel A: share of ordered pair-steps per interaction label (confronting, chasing, fleeing, ...)."""
    labels = _rows(ax, tables["labels"], ["fraction"], "patchy4 labels")
    if labels is None:
        return
    import seaborn as sns

    undefined = labels["label"] == "undefined"
    if (labels.loc[undefined, "n_steps"] == 0).all():  # a bar of zeros only when coinciding centres never occur
        labels = labels[~undefined]

    palette = _colours(labels["condition"])
    sns.barplot(labels.assign(percent=100 * labels["fraction"]), x="label", y="percent", hue="condition",
                palette=palette, legend=len(palette) > 1, ax=ax)
    ax.tick_params(axis="x", labelrotation=30)
    ax.set_xlabel("pair label (heading vs bearing)")
    ax.set_ylabel("pair-steps (%)")
    ax.set_title(f"Ethogram ({int(labels['n_steps'].sum())} pair-steps)")


def trajectories(tables: dict[str, pd.DataFrame], ax) -> None:
    """Panel B: the paths of every agent in the first episode (start: circle), pellets grey, eaten ones
    crossed in the eater's colour; line width grows with body size."""
    steps, food = tables["steps"], tables["food"]
    if steps.empty:
        _missing(ax, "patchy4 steps table is empty")
        return
    condition, episode = steps.sort_values(["condition", "episode"])[["condition", "episode"]].iloc[0]
    run = steps[(steps["condition"] == condition) & (steps["episode"] == episode)].sort_values("t")
    pellets = food[(food["condition"] == condition) & (food["episode"] == episode)]
    ax.scatter(pellets["x_cm"], pellets["y_cm"], s=3, color="0.75", edgecolors="none", zorder=1)
    for agent, path in run.groupby("agent"):
        size, colour = float(path["size"].iloc[0]), agent_colour(agent)
        ax.plot(path["x_cm"], path["y_cm"], color=colour, lw=0.4 + 1.2 * size, alpha=0.85, zorder=2,
                label=f"{agent}: size {size:.2f}")
        ax.plot(path["x_cm"].iloc[0], path["y_cm"].iloc[0], "o", color=colour, ms=3, zorder=3)
        eaten = pellets[pellets["eaten_by"] == agent]
        ax.scatter(eaten["x_cm"], eaten["y_cm"], s=10, marker="x", color=colour, linewidths=0.7, zorder=3)
    arena = _condition_config(tables, FORAGING, condition).arena
    ax.set_xlim(0, arena.width_cm)
    ax.set_ylim(0, arena.height_cm)
    ax.set_aspect("equal")
    ax.set_xlabel("x (cm)")
    ax.set_ylabel("y (cm)")
    ax.set_title(f"Trajectories (episode {episode})")
    ax.legend(title="agent", loc="center left", bbox_to_anchor=(1.0, 0.5), fontsize=6, title_fontsize=6)


# ------------------------------------------------------------ C, D: IDIs
def _idi_fractions(ax, hist: pd.DataFrame) -> bool:
    """One stairs line per (source, condition) of an idi_histogram table: the fraction of its IDIs per bin.

    False when no source has an IDI in the histogram's range.
    """
    colours = _colours(hist.loc[hist["source"] == "agents", "condition"].dropna().tolist() or ["agents"])
    drawn = False
    for (source, condition), h in hist.groupby(["source", "condition"], dropna=False, sort=True):
        h = h.sort_values("bin_lo_ms")
        if not h["count"].sum():
            continue
        real = source == "real_fish"
        label = SOURCE_LABELS.get(source, source) + ("" if real or len(colours) == 1 else f", {condition}")
        ax.stairs((h["count"] / h["count"].sum()).to_numpy(), np.r_[h["bin_lo_ms"], h["bin_hi_ms"].iloc[-1]],
                  color=REAL_FISH_COLOUR if real else colours[condition], lw=1.0, label=label)
        drawn = True
    return drawn


def _real_fish_note(hist: pd.DataFrame) -> str:
    real = hist[hist["source"] == "real_fish"]
    return f"real fish: {_why(real, 'no IDIs in range')}" if real["count"].fillna(0).sum() == 0 else ""


def idi_histogram(tables: dict[str, pd.DataFrame], ax) -> None:
    """Panel C: fraction of inter-discharge intervals per log-spaced bin, agents and (when a table is given)
    real fish."""
    hist = tables["idi_histogram"]
    if not _idi_fractions(ax, hist):
        _missing(ax, f"wide2 IDI histogram: {_why(hist, 'no IDIs')}")
        return
    _log_axes(ax, "x")
    ax.set_xlabel("inter-discharge interval (ms)")
    ax.set_ylabel("fraction of IDIs")
    ax.set_title("IDI distribution")
    ax.legend(loc="upper right")
    if note := _real_fish_note(hist):
        ax.text(0.98, 0.5, textwrap.fill(note, 32), transform=ax.transAxes, ha="right", va="center", fontsize=6,
                color=NEUTRAL_COLOUR)


def power_law_fit(tables: dict[str, pd.DataFrame], ax) -> None:
    """Panel D: empirical complementary CDF P(IDI >= x) of the agents' IDIs (log-log) with the fitted power
    law P(IDI >= xmin) (x / xmin)^(1 - alpha) from the power_law table, and its likelihood ratios."""
    ids, fits = tables["idis"], tables["power_law"]
    ids = _rows(ax, ids, ["idi_ms"], "wide2 IDIs")
    if ids is None:
        return
    ids = ids[ids["idi_ms"] > 0]
    colours, notes = _colours(ids["condition"]), []
    for condition, sub in ids.groupby("condition", sort=True):
        x = np.sort(sub["idi_ms"].to_numpy(float))
        ccdf = 1.0 - np.arange(x.size) / x.size  # P(X >= x_i), an empirical display, not a fit
        ax.step(x, ccdf, where="post", color=colours[condition], lw=1.0, label=f"{condition} IDIs")
        fit = fits[(fits["source"] == "agents") & (fits["condition"] == condition)]
        if fit.empty or not np.isfinite(fit["alpha"].iloc[0]):
            notes.append(f"{condition}: no fit ({_why(fit, 'no power_law row')})")
            continue
        f = fit.iloc[0]
        grid = np.geomspace(f["xmin"], max(x.max(), f["xmin"] * 1.01), 50)
        anchor = np.mean(x >= f["xmin"])
        ax.plot(grid, anchor * (grid / f["xmin"]) ** (1.0 - f["alpha"]), "--", color="black", lw=0.8,
                label=f"power law, alpha {f['alpha']:.2f}")
        prefix = f"{condition}: " if len(colours) > 1 else ""
        notes += [f"{prefix}R vs lognormal {f['R_lognormal']:.2f} (p {f['p_lognormal']:.2g})",
                  f"{prefix}R vs exponential {f['R_exponential']:.2f} (p {f['p_exponential']:.2g})"]
    real = fits[fits["source"] == "real_fish"]
    notes.append(f"real fish: alpha {real['alpha'].iloc[0]:.2f}" if len(real) and np.isfinite(real["alpha"].iloc[0])
                 else textwrap.fill(f"real fish: {_why(real, 'no fit')}", 40))
    _log_axes(ax)
    ax.set_xlabel("inter-discharge interval x (ms)")
    ax.set_ylabel("P(IDI >= x)")
    ax.set_title("Power-law fit")
    ax.legend(loc="upper right")
    ax.text(0.02, 0.02, "\n".join(notes), transform=ax.transAxes, ha="left", va="bottom", fontsize=5.5)


def idi_histogram_supplement(tables: dict[str, pd.DataFrame], ax) -> None:
    """Supplement: IDI density per ms on log-log axes, the agents of both assays (four-agent patchy, two-agent
    wide) and the real fish when a table is given."""
    drawn = False
    for assay in (FORAGING, SIGNALLING):
        hist = tables[f"idi_{assay}"]
        hist = hist[hist["source"] == "agents"] if assay == FORAGING else hist  # real fish once, from wide2
        for (source, condition), h in hist.groupby(["source", "condition"], dropna=False, sort=True):
            h = h[h["density"] > 0].sort_values("bin_lo_ms")
            if h.empty:
                continue
            mid = np.sqrt(h["bin_lo_ms"] * h["bin_hi_ms"])  # geometric bin centre on a log axis
            real = source == "real_fish"
            ax.plot(mid, h["density"], "o-", ms=2, lw=0.8, color=REAL_FISH_COLOUR if real else ASSAY_COLOURS[assay],
                    label="real fish" if real else f"agents, {assay}" + ("" if condition == "control"
                                                                           else f" {condition}"))
            drawn = True
    if not drawn:
        _missing(ax, f"IDI histograms: {_why(tables[f'idi_{SIGNALLING}'], 'no IDIs')}")
        return
    _log_axes(ax)
    edges = tables[f"idi_{SIGNALLING}"]
    # the histograms' range (docs/methods/analyses.md#analysis-signalling)
    ax.set_xlim(edges["bin_lo_ms"].min(), edges["bin_hi_ms"].max())
    # the range spans more decades than panel C's: labels at 1, 2, 5 x 10^k would run into each other
    from matplotlib.ticker import LogLocator

    ax.xaxis.set_major_locator(LogLocator(subs=(1.0,)))
    ax.set_xlabel("inter-discharge interval (ms)")
    ax.set_ylabel("density (1/ms)")
    ax.set_title("IDI histograms")
    ax.legend(loc="upper right")
    if note := _real_fish_note(tables[f"idi_{SIGNALLING}"]):  # under the legend, where the densities have fallen
        ax.text(0.98, 0.72, textwrap.fill(note, 30), transform=ax.transAxes, ha="right", va="top", fontsize=6,
                color=NEUTRAL_COLOUR)


# ------------------------------------------------- E-J: EOD rate in context
def _mean_sem(ax, table: pd.DataFrame, x: str) -> None:
    """Mean +- SEM EOD rate against ``x``, one line and band per condition."""
    colours = _colours(table["condition"])
    for condition, sub in table.groupby("condition", sort=True):
        sub = sub.sort_values(x)
        mean, sem = sub["mean_hz"].to_numpy(float), np.nan_to_num(sub["sem_hz"].to_numpy(float))
        ax.plot(sub[x], mean, "-", marker="o" if x == "bin_mid_cm" else None, ms=2.5, color=colours[condition],
                label=condition if len(colours) > 1 else None)
        ax.fill_between(sub[x], mean - sem, mean + sem, color=colours[condition], alpha=0.25, lw=0)
    if len(colours) > 1:
        ax.legend(loc="best")


def _rate_vs_distance(tables: dict[str, pd.DataFrame], ax, to: str) -> None:
    table = tables["rate_by_distance"]
    rows = _rows(ax, table[table["to"] == to], ["mean_hz", "bin_mid_cm"], f"wide2 EOD rate vs {to} distance")
    if rows is None:
        return
    _mean_sem(ax, rows, "bin_mid_cm")
    ax.set_xlabel(f"distance to {DISTANCE_LABELS[to]} (cm)")
    ax.set_ylabel("EOD rate (Hz)")
    ax.set_title(f"EOD rate vs {DISTANCE_LABELS[to]}")


def rate_vs_agent(tables: dict[str, pd.DataFrame], ax) -> None:
    """Panel E: mean +- SEM EOD rate in equal bins of the distance to the nearest agent."""
    _rate_vs_distance(tables, ax, "agent")


def rate_vs_food(tables: dict[str, pd.DataFrame], ax) -> None:
    """Panel F: mean +- SEM EOD rate in equal bins of the distance to the nearest pellet."""
    _rate_vs_distance(tables, ax, "food")


def rate_vs_wall(tables: dict[str, pd.DataFrame], ax) -> None:
    """Panel G: mean +- SEM EOD rate in equal bins of the distance to the nearest wall."""
    _rate_vs_distance(tables, ax, "wall")


def _peri_event(tables: dict[str, pd.DataFrame], ax, event: str) -> None:
    table = tables["peri_event"]
    rows = _rows(ax, table[table["event"] == event], ["mean_hz", "lag_ms"], f"wide2 EOD rate around {event}")
    if rows is None:
        return
    _mean_sem(ax, rows, "lag_ms")
    ax.axvline(0, color=NEUTRAL_COLOUR, lw=0.6, ls=":")
    ax.set_xlabel(f"time from {EVENT_LABELS[event]} (ms)")
    ax.set_ylabel("EOD rate (Hz)")
    ax.set_title(f"Around {EVENT_LABELS[event]} ({int(rows['n_agents'].max())} agent-episodes)")


def peri_eating(tables: dict[str, pd.DataFrame], ax) -> None:
    """Panel H: mean +- SEM EOD rate around eating a pellet, across agent-episodes with enough events."""
    _peri_event(tables, ax, "ate")


def peri_biting(tables: dict[str, pd.DataFrame], ax) -> None:
    """Panel I: mean +- SEM EOD rate before (and after) biting another agent."""
    _peri_event(tables, ax, "bit")


def peri_bitten(tables: dict[str, pd.DataFrame], ax) -> None:
    """Panel J: mean +- SEM EOD rate around being bitten."""
    _peri_event(tables, ax, "was_bitten")


# -------------------------------------------------------- K-P: body size
def bite_heatmap(tables: dict[str, pd.DataFrame], ax) -> None:
    """Panel K: fraction of all bites from each biter size rank to each victim size rank (counts written in)."""
    import seaborn as sns

    table = tables["bite_matrix"]
    rows = _rows(ax, table, ["fraction"], "patchy4 bite matrix")
    if rows is None:
        return
    condition = min(rows["condition"].unique())
    rows = rows[rows["condition"] == condition]
    fraction = rows.pivot(index="biter_class", columns="victim_class", values="fraction").sort_index(ascending=False)
    counts = rows.pivot(index="biter_class", columns="victim_class", values="bites").reindex_like(fraction)
    sns.heatmap(fraction, annot=counts.to_numpy(), fmt="d", cmap=HEATMAP_CMAP, vmin=0, square=True, ax=ax,
                annot_kws={"fontsize": 6}, cbar_kws={"label": "fraction of bites"},
                xticklabels=[int(c) + 1 for c in fraction.columns], yticklabels=[int(c) + 1 for c in fraction.index])
    ax.set_xlabel("victim size rank (1 = smallest)")
    ax.set_ylabel("biter size rank")
    ax.set_title(f"Bites by size ({int(rows['bites'].sum())} bites)")


def _size_scatter(ax, rows: pd.DataFrame, x: str, y: str) -> None:
    colours = _colours(rows["condition"])
    for condition, sub in rows.groupby("condition", sort=True):
        ax.scatter(sub[x], sub[y], s=10, color=colours[condition], alpha=0.7, edgecolors="none",
                   label=condition if len(colours) > 1 else None)


def win_ratio_vs_size(tables: dict[str, pd.DataFrame], ax) -> None:
    """Panel L: win ratio (bites given / (given + received)) per agent-episode against body size, with the
    Spearman test of the behaviour size_tests table."""
    rows = _rows(ax, tables["win_ratio"], ["size", "win_ratio"], "patchy4 win ratios")
    if rows is None:
        return
    _size_scatter(ax, rows, "size", "win_ratio")
    ax.axhline(0.5, color=NEUTRAL_COLOUR, lw=0.5, ls=":")
    ax.set_ylim(-0.05, 1.05)
    corner_note(ax, _stat_text(tables["size_tests"], "Spearman rho", measure="win_ratio"))
    ax.set_xlabel("body size")
    ax.set_ylabel("win ratio")
    ax.set_title("Win ratio vs size")


def food_vs_size(tables: dict[str, pd.DataFrame], ax) -> None:
    """Panel M: food eaten per agent-episode against body size, with the OLS line, slope test and R^2 of the
    behaviour food_vs_size table."""
    rows = _rows(ax, tables["food_per_agent"], ["size", "food_eaten"], "patchy4 food per agent")
    if rows is None:
        return
    _size_scatter(ax, rows, "size", "food_eaten")
    fits, colours = tables["food_vs_size"], _colours(rows["condition"])
    xs = np.array([rows["size"].min(), rows["size"].max()])
    for condition, fit in fits[fits["group"].isin(colours)].groupby("group", sort=True):
        f = fit.iloc[0]
        if np.isfinite(f["effect"]):
            ax.plot(xs, f["intercept"] + f["effect"] * xs, color=colours[condition],
                    label=f"slope {f['effect']:.2g}, R$^2$ {f['r2']:.2f}, {f['stars']}")
        else:
            corner_note(ax, f"OLS n/a: {f['reason']}")
    ax.set_xlabel("body size")
    ax.set_ylabel("food eaten per episode")
    ax.set_title(f"Food vs size ({rows[['condition', 'episode']].drop_duplicates().shape[0]} episodes)")
    if ax.get_legend_handles_labels()[0]:
        lo, hi = ax.get_ylim()
        ax.set_ylim(lo, hi + 0.12 * (hi - lo))  # room for the fit legend above the points
        ax.legend(loc="upper left")


def theil_vs_size_inequality(tables: dict[str, pd.DataFrame], ax) -> None:
    """Panel N: per episode, Theil T of the food eaten against Theil T of the agents' sizes, with the
    Spearman test of the behaviour size_tests table when it holds one (measure ``theil_t``)."""
    rows = _rows(ax, tables["theil"], ["size_theil_t", "theil_t"], "patchy4 Theil T")
    if rows is None:
        return
    _size_scatter(ax, rows, "size_theil_t", "theil_t")
    corner_note(ax, _stat_text(tables["size_tests"], "Spearman rho", measure="theil_t"))
    ax.set_xlabel("size inequality (Theil T of sizes)")
    ax.set_ylabel("food inequality (Theil T)")
    ax.set_title(f"Food vs size inequality ({len(rows)} episodes)")


def eod_rate_vs_size(tables: dict[str, pd.DataFrame], ax) -> None:
    """Panel O: mean EOD rate (EOD probability per step x the frame rate the run simulated the condition at)
    per agent-episode against body size, with the Spearman test of the behaviour size_tests table (measure
    ``eod_probability``)."""
    rows = _rows(ax, tables["eod_probability"], ["size", "eod_probability"], "patchy4 EOD probability")
    if rows is None:
        return
    fps = {c: float(_condition_config(tables, FORAGING, c).env.fps) for c in rows["condition"].unique()}
    rows = rows.assign(rate_hz=rows["eod_probability"] * rows["condition"].map(fps))
    _size_scatter(ax, rows, "size", "rate_hz")
    corner_note(ax, _stat_text(tables["size_tests"], "Spearman rho", measure="eod_probability"))
    ax.set_xlabel("body size")
    ax.set_ylabel("EOD rate (Hz)")
    ax.set_title("EOD rate vs size")


def rate_advantage(tables: dict[str, pd.DataFrame], ax) -> None:
    """Panel P: per pair of agents within 10 cm, the mean EOD-rate difference against the size difference,
    with the Spearman test of the signalling rate_tests table."""
    rows = _rows(ax, tables["rate_advantage"], ["size_advantage", "rate_advantage_hz"], "patchy4 rate advantage")
    if rows is None:
        return
    _size_scatter(ax, rows, "size_advantage", "rate_advantage_hz")
    ax.axhline(0, color=NEUTRAL_COLOUR, lw=0.5, ls=":")
    ax.axvline(0, color=NEUTRAL_COLOUR, lw=0.5, ls=":")
    stats = tables["rate_tests"]
    corner_note(ax, "\n".join(_stat_text(stats, "Spearman rho", group=c) for c in sorted(rows["condition"].unique())))
    ax.set_xlabel("size advantage (own - partner)")
    ax.set_ylabel("EOD-rate advantage (Hz)")
    ax.set_title(f"Rate vs size advantage ({len(rows)} pairs)")


# ------------------------------------------------------------------ panels
_SIG = {name: _analysis("signalling", SIGNALLING, name) for name in ("idis", "idi_histogram", "power_law",
                                                                     "rate_by_distance", "peri_event")}
_BEH = {name: _analysis("behaviour", FORAGING, name) for name in ("food_per_agent", "food_vs_size", "theil",
                                                                  "win_ratio", "bite_matrix", "eod_probability",
                                                                  "size_tests")}
_SIZE_TESTS = "Spearman test from analysis/behaviour/patchy4/size_tests"

PANELS = [
    Panel("fig3", "A", ethogram, {"labels": _analysis("interactions", FORAGING, "labels")},
          "Ethogram: share of ordered pair-steps labelled confronting, chasing, fleeing, dispersing or unaligned "
          "(heading minus bearing to the partner, pi/4 and 3pi/4 thresholds), patchy4, "
          "analysis/interactions/patchy4/labels; descriptive, no test."),
    Panel("fig3", "B", trajectories, {"steps": layout.assay_table(FORAGING, "steps"),
                                      "food": layout.assay_table(FORAGING, "food")},
          "Trajectories of the four agents in the first patchy4 episode (line width grows with size), pellets "
          "grey, eaten pellets crossed in the eater's colour; raw rollout tables steps and food, no statistic."),
    Panel("fig3", "C", idi_histogram, {"idi_histogram": _SIG["idi_histogram"]},
          "Inter-discharge intervals of the agents (and of real fish when analysis.real_fish_idis names a table) "
          "as fractions per log-spaced bin (50 bins, 10-3000 ms), wide2, analysis/signalling/wide2/idi_histogram."),
    Panel("fig3", "D", power_law_fit, {"idis": _SIG["idis"], "power_law": _SIG["power_law"]},
          "Complementary CDF of the agents' IDIs, wide2 (analysis/signalling/wide2/idis), with the power law "
          "fitted by the powerlaw package above xmin = 12 ms and its normalised log-likelihood ratios R (and p) "
          "against lognormal and exponential, from analysis/signalling/wide2/power_law."),
    Panel("fig3", "E", rate_vs_agent, {"rate_by_distance": _SIG["rate_by_distance"]},
          "EOD rate (20-step rolling mean x 83 Hz) mean +- SEM over steps in 15 bins of the nearest-agent "
          "distance (0-150 cm; bins < 5 steps dropped), wide2, analysis/signalling/wide2/rate_by_distance."),
    Panel("fig3", "F", rate_vs_food, {"rate_by_distance": _SIG["rate_by_distance"]},
          "EOD rate mean +- SEM over steps in 15 bins of the nearest-pellet distance (0-10 cm), wide2, "
          "analysis/signalling/wide2/rate_by_distance."),
    Panel("fig3", "G", rate_vs_wall, {"rate_by_distance": _SIG["rate_by_distance"]},
          "EOD rate mean +- SEM over steps in 15 bins of the wall distance (0-10 cm), wide2, "
          "analysis/signalling/wide2/rate_by_distance."),
    Panel("fig3", "H", peri_eating, {"peri_event": _SIG["peri_event"]},
          "EOD rate +-100 steps around eating, mean +- SEM across agent-episodes with >= 3 events, wide2, "
          "analysis/signalling/wide2/peri_event (event ate)."),
    Panel("fig3", "I", peri_biting, {"peri_event": _SIG["peri_event"]},
          "EOD rate +-100 steps around biting (before and after), mean +- SEM across agent-episodes with >= 3 "
          "bites, wide2, analysis/signalling/wide2/peri_event (event bit)."),
    Panel("fig3", "J", peri_bitten, {"peri_event": _SIG["peri_event"]},
          "EOD rate +-100 steps around being bitten, mean +- SEM across agent-episodes with >= 3 events, wide2, "
          "analysis/signalling/wide2/peri_event (event was_bitten)."),
    Panel("fig3", "K", bite_heatmap, {"bite_matrix": _BEH["bite_matrix"]},
          "Fraction of all bites from each biter size rank to each victim size rank within the episode (counts "
          "in the cells), patchy4, analysis/behaviour/patchy4/bite_matrix; descriptive."),
    Panel("fig3", "L", win_ratio_vs_size, {"win_ratio": _BEH["win_ratio"], "size_tests": _BEH["size_tests"]},
          "Win ratio (bites given / (given + received)) per agent-episode against body size, patchy4, "
          f"analysis/behaviour/patchy4/win_ratio; {_SIZE_TESTS} (measure win_ratio)."),
    Panel("fig3", "M", food_vs_size, {"food_per_agent": _BEH["food_per_agent"], "food_vs_size": _BEH["food_vs_size"]},
          "Food eaten per agent-episode against body size, patchy4, analysis/behaviour/patchy4/food_per_agent; "
          "OLS line, slope t-test stars and R^2 from analysis/behaviour/patchy4/food_vs_size."),
    Panel("fig3", "N", theil_vs_size_inequality, {"theil": _BEH["theil"], "size_tests": _BEH["size_tests"]},
          "Theil T of food eaten against Theil T of body sizes, one point per episode, patchy4, "
          f"analysis/behaviour/patchy4/theil; {_SIZE_TESTS} (measure theil_t) when the table holds it."),
    Panel("fig3", "O", eod_rate_vs_size, {"eod_probability": _BEH["eod_probability"],
                                          "size_tests": _BEH["size_tests"]},
          "Mean EOD rate (EOD probability per step x the frame rate the run recorded, env.fps, 83 Hz by default) "
          "per agent-episode against body size, patchy4, "
          f"analysis/behaviour/patchy4/eod_probability; {_SIZE_TESTS} (measure eod_probability)."),
    Panel("fig3", "P", rate_advantage, {"rate_advantage": _analysis("signalling", FORAGING, "rate_advantage"),
                                        "rate_tests": _analysis("signalling", FORAGING, "rate_tests")},
          "Per pair of agents while within 10 cm: mean EOD-rate difference against size difference, patchy4, "
          "analysis/signalling/patchy4/rate_advantage; Spearman test from analysis/signalling/patchy4/rate_tests."),
    Panel("supp", "idi_histogram", idi_histogram_supplement,
          {f"idi_{FORAGING}": _analysis("signalling", FORAGING, "idi_histogram"),
           f"idi_{SIGNALLING}": _SIG["idi_histogram"]},
          "IDI density (per ms, log-log, 50 log-spaced bins 10-3000 ms) of the agents in patchy4 and wide2 and of "
          "real fish when analysis.real_fish_idis names a table, analysis/signalling/<assay>/idi_histogram."),
]
