"""The contact sheet of a run: every registered panel's PNG as a thumbnail with its id, on one page.

A reader checks all panels at a glance (``efish contact-sheet``). Panels come
in :data:`efish.figures.registry.PANELS` order from
``figures/<run>/<figure>/<panel>.png``; a panel whose PNG is absent (its
assays do not run at this scale, or its job has not run) keeps its place and
says "not drawn at this scale".
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from pathlib import Path

import numpy as np

from ..io import atomic_path
from .panel import Panel
from .style import NEUTRAL_COLOUR, panel_style

COLUMNS = 6
THUMB_IN = (2.2, 1.76)  # a panel's 3.5 x 2.8 in, scaled down
LABEL_IN = 0.25          # room under each thumbnail for its id
TITLE_IN = 0.4          # room above the grid for the title
SHEET_DPI = 150
NOT_DRAWN = "not drawn at this scale"


def panel_png(figures: Path, panel: Panel) -> Path:
    """Where the ``panel`` rule writes a panel's PNG."""
    return Path(figures) / panel.figure / f"{panel.name}.png"


def thumbnail(path: Path, width_px: int) -> np.ndarray:
    """The PNG at ``path`` scaled down to ``width_px`` wide (RGB), so a page of many panels stays small."""
    from PIL import Image

    with Image.open(path) as im:
        im = im.convert("RGB")
        im.thumbnail((width_px, width_px))
        return np.asarray(im)


def sheet_figure(figures: Path, panels: Sequence[Panel]):
    """The contact sheet as a matplotlib figure (one axes per panel, in ``panels`` order); the caller closes it.

    Each axes holds the thumbnail, or the words "not drawn at this scale" when the PNG is absent, and the
    panel id under it."""
    import matplotlib.pyplot as plt

    if not panels:
        raise ValueError("the contact sheet needs at least one panel")
    cols = min(COLUMNS, len(panels))
    rows = math.ceil(len(panels) / cols)
    width, height = cols * THUMB_IN[0], rows * (THUMB_IN[1] + LABEL_IN) + TITLE_IN
    fig, axes = plt.subplots(rows, cols, figsize=(width, height), squeeze=False,
                             gridspec_kw={"hspace": LABEL_IN / THUMB_IN[1] + 0.05, "wspace": 0.05})
    # margins in inches, not fractions: a tall sheet would otherwise waste its top and bottom
    fig.subplots_adjust(left=0.05 / width, right=1 - 0.05 / width, top=1 - TITLE_IN / height,
                        bottom=LABEL_IN / height)
    drawn = sum(panel_png(figures, p).is_file() for p in panels)
    fig.suptitle(f"{figures}: {drawn} of {len(panels)} panels drawn", y=1 - 0.08 / height, va="top",
                 fontsize=11)
    for ax, panel in zip(axes.flat, panels, strict=False):
        path = panel_png(figures, panel)
        ax.set_xticks([])
        ax.set_yticks([])
        if path.is_file():
            ax.imshow(thumbnail(path, int(THUMB_IN[0] * SHEET_DPI)))
            ax.set_axis_off()
        else:
            ax.text(0.5, 0.5, NOT_DRAWN, ha="center", va="center", transform=ax.transAxes, fontsize=8,
                    color=NEUTRAL_COLOUR)
            for spine in ax.spines.values():
                spine.set(visible=True, color=NEUTRAL_COLOUR, linestyle="--", linewidth=0.8)
        ax.text(0.5, -0.03, panel.key, ha="center", va="top", transform=ax.transAxes, fontsize=9,
                fontweight="bold")
    for ax in axes.flat[len(panels):]:
        ax.set_axis_off()
    return fig


def write_contact_sheet(figures: Path, out: Path, panels: Sequence[Panel] | None = None) -> tuple[int, int]:
    """Write the contact sheet of the panels in ``figures`` to the PNG ``out`` (atomically); ``panels``
    defaults to every registered panel. Returns (panels drawn, panels not drawn)."""
    from .registry import PANELS

    figures, out = Path(figures), Path(out)
    if not figures.is_dir():
        raise ValueError(f"no figure folder {figures}: draw the panels first (efish figure ...) or pass --figures")
    if out.suffix.lower() != ".png":
        raise ValueError(f"the contact sheet is a PNG: --out must end in .png, got {out}")
    panels = list(PANELS.values()) if panels is None else list(panels)
    with panel_style():
        import matplotlib.pyplot as plt

        fig = sheet_figure(figures, panels)
        with atomic_path(out) as tmp:
            fig.savefig(tmp, format="png", dpi=SHEET_DPI)
        plt.close(fig)
    drawn = sum(panel_png(figures, p).is_file() for p in panels)
    return drawn, len(panels) - drawn
