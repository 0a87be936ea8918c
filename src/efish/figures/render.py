"""Load a panel's tables, draw it, save PNG and PDF atomically; the same for a whole-figure page."""

from __future__ import annotations

import math
from collections.abc import Sequence
from pathlib import Path

import pandas as pd

from ..io import atomic_path, read_parquet
from .registry import PANELS, Panel
from .style import panel_style

#: One journal column wide (3.5 in), so fonts of 7-8 pt are legible at print size.
PANEL_SIZE_IN = (3.5, 2.8)


Seeds = int | Sequence[int]  # the trained seeds' numbers, or their count n for seeds 1..n


def seed_numbers(seeds: Seeds) -> list[int]:
    """The seed numbers ``{seed}`` expands over: ``seeds`` itself, or 1..seeds for a count."""
    return list(range(1, seeds + 1)) if isinstance(seeds, int) else [int(s) for s in seeds]


def input_paths(panel: Panel, results: Path, seeds: Seeds) -> dict[str, list[Path]]:
    """Every file a panel reads (:attr:`Panel.tables`: its inputs and the conditions of its assays): ``{seed}``
    expands over the trained seeds (:func:`seed_numbers`)."""
    return {name: [results / path.format(seed=s) for s in seed_numbers(seeds)] if "{seed}" in path
            else [results / path] for name, path in panel.tables.items()}


def check_inputs(panel: Panel, results: Path, seeds: Seeds) -> None:
    """One clear error naming the first table of ``panel`` that does not exist (a missing conditions table: rerun
    the assay, which writes it; a missing settings table: rerun the analysis)."""
    for name, paths in input_paths(panel, results, seeds).items():
        for path in paths:
            if not path.is_file():
                hint = ("rerun the assay, which records its conditions" if name in panel.conditions else
                        "rerun the analysis, which records its settings" if name in panel.settings else
                        "run the pipeline first")
                raise ValueError(f"panel {panel.key} needs {path}, which does not exist ({hint})")


def load_tables(panel: Panel, results: Path, seeds: Seeds) -> dict[str, pd.DataFrame]:
    """The panel's tables (:attr:`Panel.tables`); a per-seed path gets a ``seed`` column. A missing file is one
    clear error (:func:`check_inputs`)."""
    check_inputs(panel, results, seeds)
    declared = panel.tables
    numbers = seed_numbers(seeds)
    return {name: pd.concat([read_parquet(path).assign(seed=numbers[i]) if "{seed}" in declared[name]
                             else read_parquet(path) for i, path in enumerate(paths)], ignore_index=True)
            for name, paths in input_paths(panel, results, seeds).items()}


def render_panel(key: str, results: Path, out: Path, seeds: Seeds) -> list[Path]:
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


def render_figure(figure: str, panels: list[Panel], results: Path, out: Path, seeds: Seeds) -> dict[str, list[Path]]:
    """Every panel of ``figure`` (``out/<figure>/<panel>.png`` and ``.pdf``) and its page (``out/<figure>.png``
    and ``.pdf``, the panels lettered by their ids), each panel's tables read once for both drawings and let go
    before the next panel's (a paper-scale steps table is large). Every input is checked to exist before anything
    is drawn, so a missing table writes nothing. Returns panel key (and ``figure`` for the page) -> files."""
    if not panels:
        raise ValueError(f"figure {figure!r} has no panels to draw at this scale")
    for panel in panels:
        check_inputs(panel, results, seeds)
    written = {}
    cols = min(3, len(panels))
    rows = math.ceil(len(panels) / cols)
    with panel_style() as plt:
        page = plt.figure(figsize=(PANEL_SIZE_IN[0] * cols, PANEL_SIZE_IN[1] * rows), layout="constrained")
        for i, panel in enumerate(panels, 1):
            tables = load_tables(panel, results, seeds)
            fig = draw_panel(panel, tables, plt)
            written[panel.key] = save_figure(fig, out / panel.figure / panel.name)
            plt.close(fig)
            ax = page.add_subplot(rows, cols, i, projection=panel.projection)
            panel.draw(tables, ax)
            ax.text(-0.15, 1.05, panel.name if len(panel.name) == 1 else "", transform=ax.transAxes,
                    fontweight="bold", fontsize=11)
        written[figure] = save_figure(page, out / figure)
        plt.close(page)
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

