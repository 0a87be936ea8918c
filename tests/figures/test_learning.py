"""The claims along training as figures (efish.figures.learning), one per figure of the paper's claims: one axes per
part titled with its claim, part and trend, effect against env steps on a log axis, the paper's side named; a part
without any effect says so."""

from __future__ import annotations

import numpy as np
import pytest

from efish.claims.registry import CLAIM_FIGURES
from efish.claims.stages import claims_by_stage, stage_trends
from efish.figures.learning import (
    VERDICT_COLOURS,
    by_group,
    claims_by_stage_figure,
    group_title,
    plot_claims_by_stage,
)
from efish.figures.style import panel_style

from ..claims.test_claims_stages import STEPS, stage_parts

PARTS = {("C3", "alignment"): (-1, [-0.1, -0.2, -0.3, -0.4]),
         ("C10", "K off (equivalent)"): (0, [1.5, 0.9, 0.4, 0.05]),
         ("C7", "win ratio slope, patchy4"): (+1, [np.nan] * 4)}


@pytest.fixture
def stacked():
    return claims_by_stage(stage_parts(PARTS), STEPS)


def test_every_part_has_its_axes_with_claim_part_and_trend(stacked):
    with panel_style() as plt:
        fig = claims_by_stage_figure(stacked, plt=plt)
        try:
            axes = {ax.get_title().split("\n")[0]: ax for ax in fig.axes}
            assert list(axes) == ["C3: alignment", "C7: win ratio slope, patchy4", "C10: K off (equivalent)"]
            c3 = axes["C3: alignment"]
            assert c3.get_title().endswith("moving toward the paper's sign") and c3.get_xscale() == "log"
            assert c3.get_ylabel() == "effect (paper: < 0)" and axes["C10: K off (equivalent)"].get_ylabel() == \
                "effect (paper: 0)"
            assert c3.get_ylim()[0] < -0.4 and c3.get_ylim()[1] > 0  # the effects and the line at 0
            assert [t.get_text() for t in c3.get_xticklabels()] == ["25k", "50k", "75k", "100k"]
            empty = axes["C7: win ratio slope, patchy4"]
            assert empty.get_title().endswith("not decidable")
            assert any("no finite effect at any stage" in t.get_text() for t in empty.texts)
            assert [t.get_text() for t in fig.legends[0].get_texts()] == ["holds"]
            assert "holds" in VERDICT_COLOURS
        finally:
            plt.close(fig)


def test_each_figure_of_claims_is_written_as_png_and_pdf(stacked, tmp_path):
    """One figure per group of CLAIM_FIGURES, fig2 .. fig6: C3's in fig2, C7's in fig3, C10's in fig4; fig5 and
    fig6, whose claims have no part here, are written too (the pipeline declares them), saying so."""
    written = plot_claims_by_stage(stacked, tmp_path / "learning" / "claims_by_stage", stage_trends(stacked))
    names = [f"claims_by_stage_{g}.{ext}" for g in CLAIM_FIGURES for ext in ("png", "pdf")]
    assert list(CLAIM_FIGURES) == ["fig2", "fig3", "fig4", "fig5", "fig6"]
    assert [p.name for p in written] == names and all(p.stat().st_size > 1000 for p in written)
    assert sorted(p.name for p in (tmp_path / "learning").iterdir()) == sorted(names)


def test_a_group_gets_the_parts_of_its_claims_only_under_its_title(stacked):
    tables = by_group(stacked)
    assert list(tables) == list(CLAIM_FIGURES)
    assert {g: sorted(set(t["claim"])) for g, t in tables.items()} == {
        "fig2": ["C3"], "fig3": ["C7"], "fig4": ["C10"], "fig5": [], "fig6": []}
    with panel_style() as plt:
        fig = claims_by_stage_figure(tables["fig4"], plt=plt, title=group_title("fig4", CLAIM_FIGURES["fig4"]))
        try:
            assert [ax.get_title().split("\n")[0] for ax in fig.axes] == ["C10: K off (equivalent)"]
            assert fig.get_suptitle() == "Fig. 4 (C10-C13) along training"
        finally:
            plt.close(fig)


def test_a_claim_in_no_group_and_an_empty_table_are_refused(stacked, tmp_path):
    with pytest.raises(ValueError, match="the claims C7 are in no group of a, b"):
        plot_claims_by_stage(stacked, tmp_path / "claims_by_stage", groups={"a": ["C3"], "b": ["C10"]})
    with pytest.raises(ValueError, match="no part to draw"):
        plot_claims_by_stage(stacked.iloc[0:0], tmp_path / "claims_by_stage")
    assert not list(tmp_path.iterdir())


def test_an_empty_table_is_refused(stacked):
    with panel_style() as plt, pytest.raises(ValueError, match="no part to draw"):
        claims_by_stage_figure(stacked.iloc[0:0], plt=plt)
