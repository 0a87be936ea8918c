"""Fig 1 and its supplement panels: each renders from the synthetic results plus coarse scene tables computed
here by the scene code, labels its axes (or is a schematic), and draws the table's numbers."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from matplotlib.colors import to_rgb

from efish.config.schema import SensorsConfig
from efish.figures import fig1
from efish.figures.registry import PANELS
from efish.figures.render import load_tables, render_panel
from efish.figures.style import RECEPTOR_COLOURS, panel_style
from efish.io import write_parquet_tables
from efish.rollout.scenes import build_scene, compose_scene, to_arrow

#: coarse grids: the panels' shapes, not their resolution, are under test
COARSE = {"eod_objects": ["scene.resolution_cm=1"], "eod_walls": ["scene.resolution_cm=1"],
          "full_scene": ["scene.resolution_cm=1"], "sensor_layout": [], "food_layouts": [],
          "sensing_range": ["scene.range_points=32", "scene.bearings=12"]}
KEYS = [p.key for p in fig1.PANELS]


@pytest.fixture(scope="module")
def results(synthetic_results) -> Path:
    """The synthetic results with every scene Fig 1 reads, computed by ``efish.rollout.scenes``."""
    for name, overrides in COARSE.items():
        table = build_scene(compose_scene(name, overrides), overrides)
        write_parquet_tables({name: to_arrow(table)}, synthetic_results / "scenes")
    return synthetic_results


def draw(key: str, results: Path):
    """Draw panel ``key`` on a fresh axes; return the figure and axes (close the figure after use)."""
    panel = PANELS[key]
    tables = load_tables(panel, results, seeds=2)
    with panel_style() as plt:
        fig = plt.figure(figsize=(3.5, 2.8), layout="constrained")
        ax = fig.add_subplot(projection=panel.projection)
        panel.draw(tables, ax)
        fig.canvas.draw()
    return fig, ax, tables


def labelled(ax) -> bool:
    return bool(ax.get_xlabel()) and bool(ax.get_ylabel())


def test_every_panel_of_spec_fig1_and_the_two_supplement_panels_are_registered():
    assert KEYS == [f"fig1/{c}" for c in "ABCDEFGH"] + ["supp/sensing_range", "supp/interaction_sketch"]
    assert all(PANELS[k].caption for k in KEYS)


@pytest.mark.parametrize("key", KEYS)
def test_panel_renders_with_labelled_axes_or_as_a_schematic(key, results, tmp_path):
    written = render_panel(key, results, tmp_path, seeds=2)
    assert all(p.stat().st_size > 0 for p in written)
    fig, ax, _ = draw(key, results)
    children = ax.child_axes  # insets (C, H, the sensing-range zoom)
    schematic = not PANELS[key].inputs
    if schematic:
        assert not ax.axison and ax.get_title()
    else:
        assert labelled(ax) or (children and all(labelled(c) for c in children))
    fig.clf()


def test_field_panels_draw_the_table_magnitude(results):
    fig, ax, tables = draw("fig1/E", results)
    grid = tables["scene"].query("element == 'grid'").sort_values(["y_cm", "x_cm"])
    mesh = ax.collections[0]
    expected = np.log10(np.hypot(grid["ex_v_m"], grid["ey_v_m"])).to_numpy()
    drawn = np.ma.filled(mesh.get_array().astype(float), np.nan).ravel()
    water = ~grid["inside_body"].to_numpy()
    np.testing.assert_allclose(drawn[water], expected[water])
    assert np.isnan(drawn[~water]).all()
    fig.clf()


def test_distortion_panel_is_the_ratio_to_the_free_field(results):
    fig, ax, tables = draw("fig1/D", results)
    grid = tables["scene"].query("element == 'grid' and not inside_body").sort_values(["y_cm", "x_cm"])
    drawn = np.ma.compressed(ax.collections[0].get_array())
    ratio = np.hypot(grid["ex_v_m"], grid["ey_v_m"]) / np.hypot(grid["ex_free_v_m"], grid["ey_free_v_m"])
    np.testing.assert_allclose(np.sort(drawn), np.sort(np.log2(ratio)))
    fig.clf()


def test_sensor_layout_draws_every_sensor(results):
    fig, ax, _ = draw("fig1/F", results)
    counts = sorted(len(c.get_offsets()) for c in ax.collections)
    se = SensorsConfig()
    assert counts == sorted([se.mormyromast.count, se.ampullary.count, se.knollenorgan.count])
    fig.clf()


def test_food_layouts_draw_every_pellet(results):
    fig, ax, tables = draw("fig1/C", results)
    drawn = sum(len(c.get_offsets()) for a in ax.child_axes for c in a.collections)
    assert drawn == (tables["scene"]["element"] == "pellet").sum()
    fig.clf()


def test_raster_has_every_eod_of_the_episode(results):
    fig, ax, tables = draw("fig1/H", results)
    steps = tables["steps"]
    condition = min(steps["condition"].unique())
    run = steps[(steps["condition"] == condition) & (steps["episode"] == steps["episode"].min())]
    raster = next(a for a in ax.child_axes if a.get_xlabel() == "time (s)")
    events = sum(len(c.get_positions()) for c in raster.collections)
    assert events == int(run["eod"].sum())
    fig.clf()


def test_sensing_range_contours_every_receptor_class(results):
    fig, ax, _ = draw("supp/sensing_range", results)
    colours = {tuple(np.round(c.get_edgecolor()[0][:3], 3)) for a in [ax, *ax.child_axes] for c in a.collections
               if len(c.get_paths()) and len(c.get_edgecolor())}
    assert colours == {tuple(np.round(to_rgb(c), 3)) for c in RECEPTOR_COLOURS.values()}
    fig.clf()


def test_missing_scene_rows_say_so(results):
    panel = PANELS["fig1/E"]
    tables = {"scene": load_tables(panel, results, seeds=2)["scene"].iloc[:0]}
    with panel_style() as plt:
        fig = plt.figure()
        ax = fig.add_subplot()
        panel.draw(tables, ax)
        assert any("no data" in t.get_text() for t in ax.texts)
        plt.close(fig)
