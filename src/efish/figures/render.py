"""Load a panel's tables, draw it, save PNG and PDF atomically; the same for a whole-figure page."""

from __future__ import annotations

import math
from pathlib import Path

import pandas as pd

from ..io import atomic_path, read_parquet
from .registry import PANELS, Panel
from .style import panel_style

#: One journal column wide (3.5 in), so fonts of 7-8 pt are legible at print size.
PANEL_SIZE_IN = (3.5, 2.8)


def input_paths(panel: Panel, results: Path, seeds: int) -> dict[str, list[Path]]:
    """Every file a panel reads: ``{seed}`` expands over seeds 1..seeds."""
    return {name: [results / path.format(seed=s) for s in range(1, seeds + 1)] if "{seed}" in path
            else [results / path] for name, path in panel.inputs.items()}


def load_tables(panel: Panel, results: Path, seeds: int) -> dict[str, pd.DataFrame]:
    """The panel's tables; a per-seed path gets a ``seed`` column. A missing file is one clear error."""
    tables = {}
    for name, paths in input_paths(panel, results, seeds).items():
        frames = []
        for seed, path in enumerate(paths, 1):
            if not path.is_file():
                raise ValueError(f"panel {panel.key} needs {path}, which does not exist (run the pipeline first)")
            frame = read_parquet(path)
            frames.append(frame.assign(seed=seed) if "{seed}" in panel.inputs[name] else frame)
        tables[name] = pd.concat(frames, ignore_index=True)
    return tables


def render_panel(key: str, results: Path, out: Path, seeds: int) -> list[Path]:
    """Draw panel ``key`` (e.g. ``fig3/M``) into ``out/<figure>/<panel>.png`` and ``.pdf``."""
    panel = _panel(key)
    tables = load_tables(panel, results, seeds)
    with panel_style() as plt:
        fig = draw_panel(panel, tables, plt)
        written = save_figure(fig, out / panel.figure / panel.name)
        plt.close(fig)
    return written


def draw_panel(panel: Panel, tables: dict[str, pd.DataFrame], plt):
    """A new one-column figure with ``panel`` drawn from ``tables`` (inside :func:`panel_style`)."""
    fig = plt.figure(figsize=PANEL_SIZE_IN, layout="constrained")
    panel.draw(tables, fig.add_subplot(projection=panel.projection))
    return fig


def render_page(figure: str, panels: list[Panel], results: Path, out: Path, seeds: int) -> list[Path]:
    """All ``panels`` of one figure on one page, lettered by their ids: ``out/<figure>.png`` and ``.pdf``."""
    if not panels:
        raise ValueError(f"figure {figure!r} has no panels to draw at this scale")
    cols = min(3, len(panels))
    rows = math.ceil(len(panels) / cols)
    with panel_style() as plt:
        fig = plt.figure(figsize=(PANEL_SIZE_IN[0] * cols, PANEL_SIZE_IN[1] * rows), layout="constrained")
        for i, panel in enumerate(panels, 1):
            ax = fig.add_subplot(rows, cols, i, projection=panel.projection)
            panel.draw(load_tables(panel, results, seeds), ax)
            ax.text(-0.15, 1.05, panel.name if len(panel.name) == 1 else "", transform=ax.transAxes,
                    fontweight="bold", fontsize=11)
        written = save_figure(fig, out / figure)
        plt.close(fig)
    return written


def save_figure(fig, stem: Path) -> list[Path]:
    """``stem.png`` and ``stem.pdf``, each written to a temporary file and renamed."""
    stem.parent.mkdir(parents=True, exist_ok=True)
    written = []
    for ext in ("png", "pdf"):
        with atomic_path(stem.with_suffix(f".{ext}")) as tmp:
            fig.savefig(tmp, format=ext)
        written.append(stem.with_suffix(f".{ext}"))
    return written


def _panel(key: str) -> Panel:
    if key not in PANELS:
        raise ValueError(f"unknown panel {key!r}: choose one of {', '.join(PANELS)}")
    return PANELS[key]

