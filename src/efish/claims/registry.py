"""Every claim of the paper, in the paper's order, and the tables they read.

The one list of claims: ``efish claims``, the workflow's ``claims`` rule and the
tests take their claims from :data:`CLAIMS`. A claim is defined in the module of
its figure (:mod:`.fig2` .. :mod:`.fig6`) and listed here by hand, so adding one
is two visible lines, and importing a figure module registers nothing.
"""

from __future__ import annotations

from collections.abc import Mapping

from ..analysis.registry import ANALYSES, tables_written
from ..config.schema import AssayConfig
from ..layout import analysis_table, assay_table
from . import fig2, fig3, fig4, fig5, fig6
from .context import Claim

__all__ = ["CLAIMS", "CLAIM_FIGURES", "claim_tables", "produced_tables"]

_BY_FIGURE: dict[str, tuple[Claim, ...]] = {
    "fig2": (fig2.c1, fig2.c2, fig2.c3),
    "fig3": (fig3.c4, fig3.c5, fig3.c6, fig3.c7, fig3.c8, fig3.c9),
    "fig4": (fig4.c10, fig4.c11, fig4.c12, fig4.c13),
    "fig5": (fig5.c14, fig5.c15, fig5.c16),
    "fig6": (fig6.c17, fig6.c18, fig6.c19, fig6.c20, fig6.c21),
}
#: Claim id -> :class:`~efish.claims.context.Claim`, in the paper's order (C1 .. C21).
CLAIMS: dict[str, Claim] = {c.id: c for claims in _BY_FIGURE.values() for c in claims}
#: The paper's figure (the module that defines its claims: ``fig2`` .. ``fig6``) -> its claims' ids, in order: the
#: groups of the claims along training's figures (:func:`efish.figures.learning.plot_claims_by_stage`), one figure
#: per group. C7 (panels 3K,L and 5M,N) is figure 3's, where it is defined.
CLAIM_FIGURES: dict[str, tuple[str, ...]] = {f: tuple(c.id for c in claims) for f, claims in _BY_FIGURE.items()}


def claim_tables() -> list[str]:
    """Every table some claim reads, as paths under ``results/{run}/``, sorted."""
    return sorted({t for c in CLAIMS.values() for t in c.tables})


def produced_tables(assays: Mapping[str, AssayConfig]) -> set[str]:
    """The tables a run of these assays writes (rollout and analysis), as paths under ``results/{run}/``."""
    out = set()
    for name, assay in assays.items():
        written = tables_written(assay)
        out |= {assay_table(name, t) for t in written}
        out |= {analysis_table(a.name, name, t) for a in ANALYSES.values()
                if name in a.assays and set(a.reads) <= set(written) for t in a.written}
    return out
