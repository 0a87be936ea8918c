"""The claims along training as figures (``efish claims-by-stage --figures``): one per figure of the paper's claims
(``claims_by_stage_fig2`` .. ``_fig6``, the groups of :data:`efish.claims.registry.CLAIM_FIGURES`), one small axes
per claim part, three to a row so that a figure stays legible at a page's width.

Each axes shows a part's effect with its interval (the one its verdict reads) at every kept training
stage against env steps (log axis), points coloured by that stage's verdict, a
line at 0 and the paper's side of it shaded; the y label names that side
("effect (paper: > 0)"; "paper: 0", a part the paper reports as no
difference, and "paper: ≠ 0", any difference, shade nothing). The title is
``C3: <part>`` and the part's trend
(:func:`efish.claims.stages.stage_trends`). A part with no finite
effect at any stage says so on its axes instead of drawing nothing.

Reads the stacked table of :func:`efish.claims.stages.claims_by_stage`;
no simulator, no torch.
"""

from __future__ import annotations

import math
import re
import textwrap
from collections.abc import Mapping, Sequence
from pathlib import Path

import numpy as np
import pandas as pd

from ..claims.registry import CLAIM_FIGURES
from ..claims.stages import TRENDS, stage_trends
from .render import save_figure
from .style import NEUTRAL_COLOUR, missing, panel_style, tint

#: A verdict's colour in this figure and the claims grid (Okabe-Ito: green holds, blue absent, vermilion opposite,
#: amber inconclusive, greys for the rest), one per :data:`efish.claims.verdicts.VERDICTS`.
VERDICT_COLOURS = {"holds": "#009E73", "absent": "#0072B2", "opposite": "#D55E00", "inconclusive": "#E69F00",
                   "not decidable": NEUTRAL_COLOUR, "not run": tint(NEUTRAL_COLOUR, 0.5)}
#: Side of one part's axes, inches; at most this many axes per row. Three columns of 2.4 in at :data:`FONT` pt read
#: at about 11 px per 8 pt on a documentation page 730 px wide (four columns of the whole table, at 7 pt, did not).
AXES_IN, COLUMNS = (2.4, 2.0), 3
FONT = 8.0  # titles, labels and legend, pt; tick labels 1 pt smaller
TITLE_CHARS = 28  # a longer part label wraps (it would run past the last column's axes)
PAPER_SHADE = tint(VERDICT_COLOURS["holds"], 0.85)


def _paper_side(ax, sign: float) -> None:
    """The line at 0 and the paper's side of it shaded (after the data set the limits); the y label names it."""
    ax.axhline(0.0, color="black", lw=0.6, zorder=1)
    lo, hi = ax.get_ylim()
    lo, hi = min(lo, -0.05 * (hi - lo)), max(hi, 0.05 * (hi - lo))  # 0 always in view, with both sides
    ax.set_ylim(lo, hi)
    if np.isfinite(sign) and sign != 0:
        ax.axhspan(0.0, hi if sign > 0 else lo, color=PAPER_SHADE, zorder=0, lw=0)
    paper = "≠ 0" if not np.isfinite(sign) else "0" if sign == 0 else "> 0" if sign > 0 else "< 0"
    ax.set_ylabel(f"effect (paper: {paper})", fontsize=FONT)


def _steps(n: float) -> str:
    """Env steps in short: 2500 -> 2.5k, 3000000 -> 3M.

    >>> [_steps(n) for n in (800, 2500, 10000, 3_000_000)]
    ['800', '2.5k', '10k', '3M']
    """
    for scale, unit in ((1e9, "G"), (1e6, "M"), (1e3, "k")):
        if n >= scale:
            return f"{n / scale:.3g}{unit}"
    return f"{n:.3g}"


def draw_part(ax, rows: pd.DataFrame, title: str, trend: str) -> None:
    """One part's stages on ``ax``: effect and interval against env steps, coloured by verdict."""
    ax.set_title("\n".join([*textwrap.wrap(title, TITLE_CHARS, break_on_hyphens=False), trend]), fontsize=FONT)
    ax.tick_params(labelsize=FONT - 1)
    signs = rows["sign"].to_numpy(np.float64)
    sign = next((s for s in signs if np.isfinite(s)), np.nan)
    shown = rows[np.isfinite(rows["effect"].to_numpy(np.float64))]
    if shown.empty:
        missing(ax, "no finite effect at any stage")
        return
    for row in shown.itertuples(index=False):
        has_ci = np.isfinite(row.ci_low) and np.isfinite(row.ci_high)
        err = [[max(row.effect - row.ci_low, 0.0)], [max(row.ci_high - row.effect, 0.0)]] if has_ci else None
        ax.errorbar([row.env_steps], [row.effect], yerr=err, fmt="o", ms=4, capsize=2, lw=0.8,
                    color=VERDICT_COLOURS.get(row.verdict, NEUTRAL_COLOUR), zorder=3)
    ax.plot(shown["env_steps"], shown["effect"], color=NEUTRAL_COLOUR, lw=0.6, zorder=2)
    steps = np.unique(rows["env_steps"].to_numpy(np.float64))  # every stage, also one without an effect
    ax.set_xscale("log")
    ax.set_xlim(steps.min() / 1.3, steps.max() * 1.3)
    ax.set_xticks(steps, [_steps(n) for n in steps])
    ax.minorticks_off()
    ax.set_xlabel("env steps", fontsize=FONT)
    _paper_side(ax, sign)


def claims_by_stage_figure(stacked: pd.DataFrame, trends: pd.DataFrame | None = None, plt=None,
                           title: str | None = None):
    """The figure of every part of ``stacked`` (inside :func:`panel_style`; ``plt`` its pyplot): a grid of
    :data:`COLUMNS` axes per row, a legend of the verdicts shown, ``title`` above. ``trends`` default:
    :func:`stage_trends`."""
    trends = stage_trends(stacked) if trends is None else trends
    trend = {(c, p): t for c, p, t in zip(trends["claim"], trends["part"], trends["trend"], strict=True)}
    groups = list(stacked.groupby(["claim", "part"], sort=False))
    if not groups:
        raise ValueError("the stacked table has no part to draw")
    cols = min(COLUMNS, len(groups))
    rows = math.ceil(len(groups) / cols)
    fig = plt.figure(figsize=(AXES_IN[0] * cols, AXES_IN[1] * rows + 0.5 + 0.3 * (title is not None)),
                     layout="constrained")
    for i, ((claim, part), g) in enumerate(groups, 1):
        label = claim if part == claim else f"{claim}: {part}"
        ax = fig.add_subplot(rows, cols, i)
        draw_part(ax, g, label, trend.get((claim, part), TRENDS[-1]))
        if i + cols <= len(groups):  # the x label once per column, under its last axes
            ax.set_xlabel("")
    seen = [v for v in VERDICT_COLOURS if v in set(stacked.loc[np.isfinite(stacked["effect"]), "verdict"])]
    handles = [plt.Line2D([], [], marker="o", ls="", color=VERDICT_COLOURS[v], label=v) for v in seen]
    if handles:
        fig.legend(handles=handles, loc="outside lower center", ncols=len(handles), fontsize=FONT)
    if title is not None:
        fig.suptitle(title, fontsize=FONT + 2)
    return fig


def group_title(group: str, claims: Sequence[str]) -> str:
    """A group's figure title: ``Fig. 3 (C4-C9) along training`` for group ``fig3``.

    >>> group_title("fig3", ["C4", "C5", "C9"]), group_title("homing", ["C1"])
    ('Fig. 3 (C4-C9) along training', 'homing (C1) along training')
    """
    name = f"Fig. {m.group(1)}" if (m := re.fullmatch(r"fig(\d+)", group)) else group
    span = claims[0] if len(claims) == 1 else f"{claims[0]}-{claims[-1]}"
    return f"{name} ({span}) along training"


def by_group(stacked: pd.DataFrame, groups: Mapping[str, Sequence[str]] = CLAIM_FIGURES) -> dict[str, pd.DataFrame]:
    """``stacked``'s rows per group of claims (group -> its claims' ids), in the groups' order, each in the stacked
    order; a group none of whose claims is in ``stacked`` gets no rows. ValueError for a claim in no group."""
    group_of = {cid: g for g, claims in groups.items() for cid in claims}
    if stray := sorted(set(stacked["claim"]) - set(group_of), key=lambda c: (len(c), c)):
        raise ValueError(f"the claims {', '.join(stray)} are in no group of {', '.join(groups)}")
    of = stacked["claim"].map(group_of)
    return {g: stacked[of == g] for g in groups}


def _no_parts_figure(plt, title: str, claims: Sequence[str]):
    """A group's figure when none of its claims has a part in the table: says so (the file is still written)."""
    fig = plt.figure(figsize=(AXES_IN[0] * COLUMNS, AXES_IN[1]), layout="constrained")
    missing(fig.add_subplot(), f"no part of {', '.join(claims)} in the stacked table")
    fig.suptitle(title, fontsize=FONT + 2)
    return fig


def plot_claims_by_stage(stacked: pd.DataFrame, path: str | Path, trends: pd.DataFrame | None = None,
                         groups: Mapping[str, Sequence[str]] = CLAIM_FIGURES) -> list[Path]:
    """One :func:`claims_by_stage_figure` per group of claims (default: per figure of the paper's claims), each
    into ``<path>_<group>``.png and .pdf (``path``'s suffix, if any, is dropped), written atomically; returns the
    files, group by group. Every group gets its files, one without parts in ``stacked`` a figure saying so; a table
    without any part, or with a claim in no group, is a ValueError before anything is written."""
    if stacked.empty:
        raise ValueError("the stacked table has no part to draw")
    tables = by_group(stacked, groups)
    trends = stage_trends(stacked) if trends is None else trends
    stem = Path(path).with_suffix("")
    written = []
    with panel_style() as plt:
        for group, table in tables.items():
            title = group_title(group, list(groups[group]))
            fig = (claims_by_stage_figure(table, trends, plt, title) if len(table)
                   else _no_parts_figure(plt, title, list(groups[group])))
            try:
                written += save_figure(fig, stem.with_name(f"{stem.name}_{group}"))
            finally:
                plt.close(fig)
    return written
