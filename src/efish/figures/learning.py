"""The claims along training as a figure (``efish claims-by-stage --figures``): one small axes per claim part.

Each axes shows a part's effect with its 95% interval at every kept training
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
import textwrap
from pathlib import Path

import numpy as np
import pandas as pd

from ..claims.stages import TRENDS, stage_trends
from .render import save_figure
from .style import NEUTRAL_COLOUR, missing, panel_style, tint

#: A verdict's colour in this figure (green holds, amber weaker, vermilion fails, greys for the rest).
VERDICT_COLOURS = {"holds": "#009E73", "weaker": "#E69F00", "fails": "#D55E00", "not decidable": NEUTRAL_COLOUR,
                   "not run": tint(NEUTRAL_COLOUR, 0.5)}
#: Side of one part's axes, inches; at most this many axes per row.
AXES_IN, COLUMNS = (2.4, 2.0), 4
TITLE_CHARS = 34  # a longer part label wraps (40 ran past the last column's axes)
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
    ax.set_ylabel(f"effect (paper: {paper})", fontsize=7)


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
    ax.set_title("\n".join([*textwrap.wrap(title, TITLE_CHARS), trend]), fontsize=7)
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
    ax.set_xlabel("env steps", fontsize=7)
    _paper_side(ax, sign)


def claims_by_stage_figure(stacked: pd.DataFrame, trends: pd.DataFrame | None = None, plt=None):
    """The figure of every part of ``stacked`` (inside :func:`panel_style`; ``plt`` its pyplot): a grid of
    :data:`COLUMNS` axes per row, a legend of the verdicts shown. ``trends`` default: :func:`stage_trends`."""
    trends = stage_trends(stacked) if trends is None else trends
    trend = {(c, p): t for c, p, t in zip(trends["claim"], trends["part"], trends["trend"], strict=True)}
    groups = list(stacked.groupby(["claim", "part"], sort=False))
    if not groups:
        raise ValueError("the stacked table has no part to draw")
    cols = min(COLUMNS, len(groups))
    rows = math.ceil(len(groups) / cols)
    fig = plt.figure(figsize=(AXES_IN[0] * cols, AXES_IN[1] * rows + 0.4), layout="constrained")
    for i, ((claim, part), g) in enumerate(groups, 1):
        title = claim if part == claim else f"{claim}: {part}"
        draw_part(fig.add_subplot(rows, cols, i), g, title, trend.get((claim, part), TRENDS[-1]))
    seen = [v for v in VERDICT_COLOURS if v in set(stacked.loc[np.isfinite(stacked["effect"]), "verdict"])]
    handles = [plt.Line2D([], [], marker="o", ls="", color=VERDICT_COLOURS[v], label=v) for v in seen]
    if handles:
        fig.legend(handles=handles, loc="outside lower center", ncols=len(handles), fontsize=7)
    return fig


def plot_claims_by_stage(stacked: pd.DataFrame, path: str | Path, trends: pd.DataFrame | None = None) -> list[Path]:
    """Draw :func:`claims_by_stage_figure` into ``path``.png and .pdf (``path``'s suffix, if any, is replaced),
    each written atomically; returns the files."""
    with panel_style() as plt:
        fig = claims_by_stage_figure(stacked, trends, plt)
        try:
            return save_figure(fig, Path(path).with_suffix(""))
        finally:
            plt.close(fig)
