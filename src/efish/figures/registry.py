"""Every panel the pipeline draws, gathered from the figure modules' ``PANELS`` lists.

The workflow draws the panels a scale can draw (:func:`drawable`), grouped by
:func:`figures`, one job per figure with its page; adding a panel means writing its function and one
:class:`~efish.figures.panel.Panel` entry in its module's ``PANELS``.
Paths are relative to ``results/{run}``.
"""

from __future__ import annotations

from collections.abc import Iterable

from . import fig1, fig2, fig3, fig4, fig5, fig6, supplement
from .panel import Panel

_ALL = [p for module in (fig1, fig2, fig3, fig4, fig5, fig6, supplement) for p in module.PANELS]
PANELS: dict[str, Panel] = {p.key: p for p in _ALL}
if len(PANELS) != len(_ALL):  # two modules registering one key: the dict would silently keep the last
    raise ImportError(f"panel keys registered twice: {sorted({p.key for p in _ALL if sum(q.key == p.key for q in _ALL) > 1})}")

__all__ = ["PANELS", "Panel", "drawable", "figures", "panels_for"]


def figures(panels: Iterable[Panel] | None = None) -> dict[str, list[Panel]]:
    """Panels grouped by figure, in their order: every registered panel, or those of ``panels`` (the workflow
    groups :func:`drawable`'s so, one job per figure; efish.run_plan)."""
    grouped: dict[str, list[Panel]] = {}
    for panel in PANELS.values() if panels is None else panels:
        grouped.setdefault(panel.figure, []).append(panel)
    return grouped


def panels_for(assays: list[str], top_seed_assays: list[str] = ()) -> list[Panel]:
    """The panels a scale can draw: those whose assays are all among ``assays`` and whose top-seed tables
    are all among ``top_seed_assays`` (empty when the scale runs no top seeds)."""
    return [p for p in PANELS.values() if p.assays() <= set(assays) and p.top_seed_assays() <= set(top_seed_assays)]


def drawable(scale) -> list[Panel]:
    """The panels a scale (``cfg.scale``) draws: its assays, and its top seeds' assays when it runs top seeds."""
    return panels_for(scale.assays, scale.top_seed_assays if scale.top_seeds else ())
