"""The registry draws every panel docs/methods/figures.md#panels lists, and every registered panel draws from
real-shaped tables."""

from __future__ import annotations

import string

import pytest

from efish.config import compose
from efish.figures.registry import PANELS, drawable
from efish.figures.render import draw_panel, load_tables, render_panel
from efish.figures.style import panel_style


def letters(last: str) -> list[str]:
    return list(string.ascii_uppercase[: string.ascii_uppercase.index(last) + 1])


#: Written from docs/methods/figures.md#panels (figure -> its panel letters; the supplement's panels by name).
SPEC_13 = {
    "fig1": letters("H"),  # A training loop ... H snapshot + EOD raster
    "fig2": letters("D"),  # A homing scene ... D error angle vs normalised time
    "fig3": letters("P"),  # A ethogram ... P EOD-rate advantage vs size advantage
    "fig4": letters("N"),  # A-F ablations, G,H collective, I,J muting, K,L patchy vs uniform, M,N N-patch
    "fig5": letters("P"),  # A assay scene ... P bite rate by class
    "fig6": letters("J"),  # A PCA variance ... I,J power
    # training curves (with losses, entropy, reward components), seed landscape, top-3 seed panels,
    # sensing-range maps, IDI histogram, interaction sketch
    "supp": ["training_curves", "losses", "entropy", "reward_components", "seed_landscape", "top_seeds_food",
             "top_seeds_eod", "top_seeds_bites", "sensing_range", "idi_histogram", "interaction_sketch"],
}
SPEC_KEYS = sorted(f"{fig}/{name}" for fig, names in SPEC_13.items() for name in names)


def test_the_registry_covers_every_panel_of_spec_13():
    assert sorted(set(SPEC_KEYS) - set(PANELS)) == []


def test_the_registry_has_no_panel_spec_13_does_not_list():
    assert sorted(set(PANELS) - set(SPEC_KEYS)) == []


def test_every_panel_has_a_caption_naming_its_source():
    for panel in PANELS.values():
        assert len(panel.caption) > 40, panel.key


def test_the_laptop_scale_draws_every_panel():
    assert {p.key for p in drawable(compose(["scale=laptop"]).scale)} >= {
        k for k, p in PANELS.items() if not any(path.startswith("scenes/") for path in p.inputs.values())}


@pytest.mark.parametrize("key", sorted(k for k, p in PANELS.items()
                                       if not any(path.startswith("scenes/") for path in p.inputs.values())))
def test_every_panel_draws_from_synthetic_tables(key, synthetic_results, tmp_path):
    """No exception, both files written, and every axes with data has labelled axes (a schematic or a panel
    saying "no data" on itself is exempt)."""
    written = render_panel(key, synthetic_results, tmp_path, seeds=2)
    assert [p.suffix for p in written] == [".png", ".pdf"]
    assert all(p.stat().st_size > 1000 for p in written)
    panel = PANELS[key]
    with panel_style() as plt:
        fig = draw_panel(panel, load_tables(panel, synthetic_results, seeds=2), plt)
        unlabelled = [ax for ax in fig.axes if unlabelled_axes(ax)]
        plt.close(fig)
    assert not panel.inputs or not unlabelled, f"{key} has axes with data but no x or y label"


def unlabelled_axes(ax) -> bool:
    """An axes that shows data but lacks an x or y label, and does not say why it has no data."""
    if not ax.get_visible() or any(t.get_text().startswith("no data") for t in ax.texts):
        return False
    shows_data = bool(ax.lines or ax.collections or ax.patches or ax.images)
    is_colorbar = ax.get_label() == "<colorbar>"
    if ax.name == "polar":  # angle ticks label themselves; the radial unit goes in the title
        return shows_data and not ax.get_title()
    return shows_data and not is_colorbar and not (ax.get_xlabel() and ax.get_ylabel())
