"""Every panel the pipeline draws, gathered from the figure modules' ``PANELS`` lists.

The workflow reads :data:`PANELS` to make one job per panel and one page per
figure; adding a panel means writing its function and one
:class:`~efish.figures.panel.Panel` entry in its module's ``PANELS``.
Paths are relative to ``results/{run}``.
"""

from __future__ import annotations

from . import fig1, fig2, fig3, fig4, fig5, fig6, supplement
from .panel import Panel

PANELS: dict[str, Panel] = {p.key: p for module in (fig1, fig2, fig3, fig4, fig5, fig6, supplement)
                            for p in module.PANELS}

__all__ = ["PANELS", "Panel", "figures", "panels_for"]


def figures() -> dict[str, list[Panel]]:
    """Panels grouped by figure, in registry order."""
    grouped: dict[str, list[Panel]] = {}
    for panel in PANELS.values():
        grouped.setdefault(panel.figure, []).append(panel)
    return grouped


def panels_for(assays: list[str]) -> list[Panel]:
    """The panels whose assays are all among ``assays`` (what a scale can draw)."""
    return [p for p in PANELS.values() if p.assays() <= set(assays)]
