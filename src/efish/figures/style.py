"""One look for every panel: colours per agent, size class, receptor class and condition, fixed once.

Every panel module takes its colours from here, so that an agent, a size
class or a receptor class has the same colour in every figure. Box, strip
and heat-map panels use seaborn with these palettes; :func:`panel_style`
sets a print-size theme (one column = 3.5 in, 7-8 pt text).
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping
from contextlib import contextmanager

import numpy as np
import pandas as pd

from .. import layout
from ..config.recorded import recorded_conditions, recorded_settings
from ..config.schema import AnalysisConfig, EfishConfig
from ..drawing import AGENT_COLOURS as AGENT_COLOURS  # the arena's colours: shared with the live env's render
from ..drawing import PELLET_COLOUR as PELLET_COLOUR
from ..drawing import agent_colour as agent_colour
from ..senses import SENSES
from .panel import conditions_key, settings_key

RECEPTOR_COLOURS = {sense.name: sense.colour for sense in SENSES}
SELECTED_COLOUR = "#D55E00"
NEUTRAL_COLOUR = "#7f7f7f"
#: The control (first) condition of an assay is always grey; the others take CONDITION_COLOURS in order.
CONTROL_COLOUR = "#7f7f7f"
CONDITION_COLOURS = ("#0072B2", "#D55E00", "#009E73", "#CC79A7", "#E69F00", "#56B4E9", "#F0E442")
#: Size classes from small to large (ranks within an episode, or the one-patch A-vs-B classes): one
#: sequential palette, light = small, dark = large.
SIZE_CLASS_CMAP = "viridis_r"
_ONEPATCH_SOCIAL = {"A_lt_B": "#440154", "A_eq_B": "#21918c", "A_gt_B": "#b89b00"}


def tint(colour: str, amount: float = 0.5) -> str:
    """``colour`` (``#rrggbb``) mixed with white: ``amount`` 0 is the colour, 1 is white.

    >>> tint("#000000", 0.5)
    '#808080'
    """
    rgb = [int(colour[i:i + 2], 16) for i in (1, 3, 5)]
    return "#" + "".join(f"{round(c + (255 - c) * amount):02x}" for c in rgb)


#: The one-patch size classes, and each size-matched alone control (config/assay/onepatch.yaml) in a light tint of
#: the class it is the control of: A alone at 0.75 and B alone at 0.25 go with A>B, both at 0.5 with A=B, A alone
#: at 0.25 and B alone at 0.75 with A<B (efish.analysis.onepatch.matched_alone).
_S = _ONEPATCH_SOCIAL
ONEPATCH_CLASS_COLOURS = {**_S,
                          "A_alone_75": tint(_S["A_gt_B"]), "A_alone_50": tint(_S["A_eq_B"]),
                          "A_alone_25": tint(_S["A_lt_B"]), "B_alone_25": tint(_S["A_gt_B"]),
                          "B_alone_50": tint(_S["A_eq_B"]), "B_alone_75": tint(_S["A_lt_B"])}
#: Decoding with the nearest food in receptor range (near) or beyond it (far), Fig 6F.
FOOD_RANGE_COLOURS = {"near": "#009E73", "far": "#7f7f7f"}
#: Sequential colour map of every heat map (bite matrices, field maps use their own diverging one).
HEATMAP_CMAP = "rocket_r"
FIELD_CMAP = "RdBu_r"

RC_PARAMS = {
    "figure.dpi": 100, "savefig.dpi": 200, "font.size": 8, "axes.titlesize": 9, "axes.labelsize": 8,
    "axes.spines.top": False, "axes.spines.right": False, "legend.frameon": False, "legend.fontsize": 7,
    "xtick.labelsize": 7, "ytick.labelsize": 7, "lines.linewidth": 1.0,
}


def size_class_colours(n: int) -> list:
    """``n`` colours for size classes 0 (smallest) .. n-1 (largest), the same ramp in every figure."""
    import matplotlib

    cmap = matplotlib.colormaps[SIZE_CLASS_CMAP]
    return [cmap(0.15 + 0.7 * i / max(n - 1, 1)) for i in range(n)]


def condition_palette(conditions: Iterable, control=None) -> dict:
    """Colour per condition: ``control`` (default: the first) grey, the rest in CONDITION_COLOURS order."""
    conditions = list(dict.fromkeys(conditions))
    control = conditions[0] if control is None and conditions else control
    others = [c for c in conditions if c != control]
    palette = {c: CONDITION_COLOURS[i % len(CONDITION_COLOURS)] for i, c in enumerate(others)}
    if control in conditions:
        palette[control] = CONTROL_COLOUR
    return palette


def stars_for(stats: pd.DataFrame, **where) -> str:
    """The ``stars`` of the one statistic row matching ``where`` (e.g. ``group="M_A"``), ``"n/a"`` if absent.

    Panels never recompute a test: they read its stars from the analysis's statistic table.
    """
    rows = stats
    for column, value in where.items():
        if column not in rows.columns:
            return "n/a"
        rows = rows[rows[column] == value]
    return str(rows["stars"].iloc[0]) if len(rows) and "stars" in rows.columns else "n/a"


def annotate_stars(ax, x: float, y: float, text: str, x2: float | None = None) -> None:
    """Stars above a group at ``x`` (or a bracket from ``x`` to ``x2``) at data height ``y``."""
    if x2 is not None:
        ax.plot([x, x, x2, x2], [y * 0.98, y, y, y * 0.98], color="black", lw=0.6)
        x = (x + x2) / 2
    ax.text(x, y, text, ha="center", va="bottom", fontsize=7)


@contextmanager
def panel_style():
    """Headless backend and the shared rc parameters, restored afterwards."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    import seaborn as sns

    with plt.rc_context(sns.axes_style("ticks")), plt.rc_context(RC_PARAMS):
        yield plt


def corner_note(ax, text: str, headroom: float = 0.09) -> None:
    """A statistic's text in the top-left corner, with room made above the data (``headroom`` of the y-range
    per line) so that no point hides under it. Call it after the data is drawn and any y-limits are set."""
    lines = text.count("\n") + 1
    lo, hi = ax.get_ylim()
    if ax.get_yscale() == "linear":
        ax.set_ylim(lo, hi + headroom * lines * (hi - lo))
    ax.text(0.02, 0.98, text, transform=ax.transAxes, va="top", ha="left", fontsize=6)


def missing(ax, what: str) -> None:
    """Say on the panel that its data is not there, instead of drawing anything made up."""
    ax.text(0.5, 0.5, f"no data:\n{what}", ha="center", va="center", transform=ax.transAxes,
            color=NEUTRAL_COLOUR, fontsize=8, wrap=True)
    ax.set_xticks([])
    ax.set_yticks([])


def finite(values) -> np.ndarray:
    """The finite entries of ``values`` as floats (NaN rows of analysis tables carry a ``reason`` instead)."""
    x = np.asarray(values, dtype=float)
    return x[np.isfinite(x)]


# ----------------------------------------------- shared drawing patterns (Figs 4-6)
#: Group sizes N = 1, 2, ... (the groupsize assay) on one sequential ramp, distinct from the size-class one.
GROUP_SIZE_CMAP = "crest"


def group_size_colours(sizes: Iterable[int]) -> dict:
    """Colour per group size, light (smallest N) to dark (largest N), the same in every panel."""
    import matplotlib
    import seaborn  # noqa: F401  (registers "crest" with matplotlib)

    sizes = sorted({int(s) for s in sizes})
    cmap = matplotlib.colormaps[GROUP_SIZE_CMAP]
    return {s: cmap(0.15 + 0.75 * i / max(len(sizes) - 1, 1)) for i, s in enumerate(sizes)}


def box_strip(ax, data: pd.DataFrame, x: str, y: str, order: list, palette: dict,
              stars: dict | None = None, labels: dict | None = None) -> bool:
    """One box (no fliers) per ``x`` category in ``order`` with every value of ``y`` as a point on it.

    ``stars`` maps a category to the text drawn above it (read by the caller
    from an analysis statistic table, never computed here); ``labels`` maps a
    category to its tick label. A category without a finite value keeps its
    place (an empty slot). When no category has a finite value the panel says
    so (the first non-empty ``reason`` of ``data``) and False is returned.
    """
    import warnings

    import seaborn as sns

    if x not in data or y not in data:
        raise ValueError(f"box_strip needs columns {x!r} and {y!r}, the table has {list(data.columns)}")
    frame = data[data[x].isin(order)]
    frame = frame.assign(**{y: pd.to_numeric(frame[y], errors="coerce")})
    values = finite(frame[y])
    if not values.size:
        reasons = [r for r in data.get("reason", pd.Series(dtype=str)).astype(str) if r and r != "nan"]
        missing(ax, reasons[0] if reasons else f"no finite {y}")
        return False
    common = {"data": frame, "x": x, "y": y, "order": order, "hue": x, "hue_order": order, "palette": palette,
              "legend": False, "ax": ax}
    with warnings.catch_warnings():
        # seaborn 0.13 passes matplotlib's deprecated ``vert`` to boxplot (a warning from matplotlib 3.11 on)
        warnings.filterwarnings("ignore", message="vert: bool was deprecated", category=DeprecationWarning)
        sns.boxplot(**common, fill=False, showfliers=False, width=0.6, linewidth=0.8)
    sns.stripplot(**common, size=3, jitter=0.2, alpha=0.8, linewidth=0.3, edgecolor="white")
    if stars:
        lo, hi = float(values.min()), float(values.max())
        pad = (hi - lo) * 0.06 or max(abs(hi), 1.0) * 0.06
        for i, group in enumerate(order):
            if group in stars:
                top = finite(frame.loc[frame[x] == group, y])
                annotate_stars(ax, i, (top.max() if top.size else hi) + pad, stars[group])
        ax.set_ylim(top=hi + 4 * pad)
    ax.set_xticks(range(len(order)), [(labels or {}).get(g, str(g)) for g in order])
    return True


def mean_lines(ax, data: pd.DataFrame, x: str, y: str, hue: str, palette: dict, styles: dict | None = None) -> bool:
    """Every value of ``y`` against a numeric ``x`` as faint points, and the mean +- SEM per ``hue`` as a line.

    The ``hue`` levels (those of ``palette`` present in the data, in its order)
    are shifted apart along x by a tenth of the smallest x step so that equal
    means stay visible; ``styles`` maps a level to a line style (e.g. Knollenorgans
    off dashed). When no value is finite the panel says so and False is returned.
    """
    frame = data.assign(**{y: pd.to_numeric(data[y], errors="coerce")}).dropna(subset=[y])
    if frame.empty:
        reasons = [r for r in data.get("reason", pd.Series(dtype=str)).astype(str) if r and r != "nan"]
        missing(ax, reasons[0] if reasons else f"no finite {y}")
        return False
    levels = [h for h in palette if h in set(frame[hue])]
    xs = np.unique(frame[x].to_numpy(float))
    step = float(np.diff(xs).min()) if len(xs) > 1 else 1.0
    rng = np.random.default_rng(0)  # fixed jitter: the same drawing on every run
    for i, level in enumerate(levels):
        sub = frame[frame[hue] == level]
        shift = (i - (len(levels) - 1) / 2) * 0.1 * step
        jitter = rng.uniform(-0.03, 0.03, len(sub)) * step
        ax.scatter(sub[x].to_numpy(float) + shift + jitter, sub[y], s=5, color=palette[level], alpha=0.4,
                   edgecolors="none")
        stats = sub.groupby(x)[y].agg(["mean", "sem"])
        ax.errorbar(stats.index.to_numpy(float) + shift, stats["mean"].to_numpy(float),
                    yerr=stats["sem"].fillna(0.0).to_numpy(float),
                    color=palette[level], marker="o", ms=3, capsize=2, lw=1.0, ls=(styles or {}).get(level, "-"),
                    label=str(level))
    ax.set_xticks(xs)
    return True


# ------------------------------------------- assay conditions: configs and display order
def assay_conditions(tables: Mapping[str, pd.DataFrame], assay: str) -> Mapping[str, EfishConfig]:
    """The config of every condition of ``assay`` as the run resolved it (with every override it had), in the
    assay's order (the first is the control), from the panel's ``conditions/<assay>`` table
    (``assays/<assay>/conditions.parquet``, :attr:`efish.figures.panel.Panel.conditions`). Panels of Figs 3-6
    read roles, sizes, arena, fps and order here; nothing is composed."""
    key, path = conditions_key(assay), layout.assay_table(assay, "conditions")
    if key not in tables:
        raise ValueError(f"the panel's tables hold no {key} ({path}): a panel that reads assay {assay}'s "
                         f"conditions but no other table of it names {path} in its inputs; an older run lacks "
                         "the file: rerun the assay")
    return recorded_conditions(tables[key], path)


def analysis_settings(tables: Mapping[str, pd.DataFrame], analysis: str, assay: str) -> AnalysisConfig:
    """The analysis settings (``cfg.analysis``) the job of ``analysis`` on ``assay`` ran with, from the panel's
    ``settings/<analysis>/<assay>`` table (its ``analysis_settings.parquet``,
    :attr:`efish.figures.panel.Panel.settings`): a threshold a panel names is the one its table was computed
    under, whatever the assay recorded or the schema says."""
    key, path = settings_key(analysis, assay), layout.analysis_settings(analysis, assay)
    if key not in tables:
        raise ValueError(f"the panel's tables hold no {key} ({path}): a panel reads the settings of the analyses "
                         "whose tables it names; an older run lacks the file: rerun the analysis")
    return recorded_settings(tables[key], path)


def condition_order(tables: Mapping[str, pd.DataFrame], assay: str, present, control=None) -> list:
    """Conditions present in a table: ``control`` first, then the assay's recorded order, then any others
    sorted."""
    present = list(dict.fromkeys(present))
    listed = [c for c in assay_conditions(tables, assay) if c in present]
    order = listed + sorted((c for c in present if c not in listed), key=str)
    return [control, *(c for c in order if c != control)] if control in present else order
