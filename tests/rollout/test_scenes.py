"""Scene tables (efish.rollout.scenes, ``efish scene``): field maps against closed-form answers, symmetry,
insulating walls, the sensing ranges of docs/model/sensors.md#calibration-checks, and the table schema. Grids are coarse
to stay fast."""

from __future__ import annotations

import json

import numpy as np
import pandas as pd
import pyarrow.parquet as pq
import pytest

from efish.cli import main
from efish.config import ConfigError
from efish.config.schema import PhysicsConfig, SensorsConfig
from efish.rollout.scenes import SCHEMA, build_scene, compose_scene, to_arrow

PH = PhysicsConfig()
K = 1 / (4 * np.pi * PH.eps0)
COARSE = ["scene.resolution_cm=1"]


def scene(name: str, *overrides: str) -> pd.DataFrame:
    return build_scene(compose_scene(name, [*COARSE, *overrides]), [*COARSE, *overrides])


def water(table: pd.DataFrame) -> pd.DataFrame:
    return table[(table["element"] == "grid") & ~table["inside_body"]]


def two_charges(x_cm, y_cm, centre_cm, heading) -> np.ndarray:
    """The EOD of docs/model/physics.md#field-sources written out: +q half a separation ahead of the centre, -q behind
    (V/m), with the softened distance of docs/model/physics.md#field-sources."""
    u = np.array([np.cos(heading), np.sin(heading)]) * PH.eod_half_separation_cm
    p = np.stack([x_cm, y_cm], axis=1)
    e = np.zeros_like(p)
    for sign in (1, -1):
        d = (p - (np.asarray(centre_cm) + sign * u)) * 0.01
        e += sign * K * PH.eod_charge_c * d / ((d ** 2).sum(axis=1, keepdims=True) + PH.softening_m ** 2) ** 1.5
    return e


def test_free_eod_is_two_point_charges_and_a_dipole_far_away():
    table = water(scene("eod_free"))
    e = table[["ex_v_m", "ey_v_m"]].to_numpy()
    exact = two_charges(table["x_cm"].to_numpy(), table["y_cm"].to_numpy(), (20.0, 15.0), 0.0)
    np.testing.assert_allclose(e, exact, rtol=1e-9, atol=1e-18)
    # beyond 10 cm the pair is a point dipole p = q * separation (the on-axis check of
    # docs/model/sensors.md#calibration-checks, every direction)
    d = (table[["x_cm", "y_cm"]].to_numpy() - (20.0, 15.0)) * 0.01
    r = np.linalg.norm(d, axis=1, keepdims=True)
    far = r[:, 0] >= 0.10
    p = np.array([PH.eod_charge_c * 2 * PH.eod_half_separation_cm * 0.01, 0.0])
    dipole = K * (3 * (d @ p)[:, None] * d / r ** 5 - p / r ** 3)
    error = np.linalg.norm(e[far] - dipole[far], axis=1) / np.linalg.norm(dipole[far], axis=1)
    assert error.max() < 0.02  # the quadrupole-free pair differs from a point dipole by O((d / r)^2)
    on_axis = table[(table["y_cm"] == 15.0) & (table["x_cm"] == 35.0)]
    assert on_axis["ex_v_m"].iloc[0] == pytest.approx(2 * K * p[0] / 0.15 ** 3, rel=0.01)


def test_one_emitter_in_free_space_is_not_distorted():
    """A body is never polarised by its own EOD: alone, without walls, the total field is the free field."""
    table = water(scene("eod_free"))
    np.testing.assert_array_equal(table["ex_v_m"], table["ex_free_v_m"])
    np.testing.assert_array_equal(table["ey_v_m"], table["ey_free_v_m"])


@pytest.mark.parametrize("walls", ["false", "true"])
def test_field_is_mirror_symmetric_about_the_emitter_axis(walls):
    table = scene("eod_free", "scene.resolution_cm=2", f"scene.walls={walls}").query("element == 'grid'")
    top = table[table["y_cm"] > 15].sort_values(["x_cm", "y_cm"])
    mirror = table.assign(y_cm=30 - table["y_cm"]).set_index(["x_cm", "y_cm"]).loc[
        list(zip(top["x_cm"], top["y_cm"], strict=True))]
    np.testing.assert_allclose(top["ex_v_m"], mirror["ex_v_m"], rtol=1e-9, atol=1e-15)
    np.testing.assert_allclose(top["ey_v_m"], -mirror["ey_v_m"], rtol=1e-9, atol=1e-15)


def test_insulating_wall_cancels_the_normal_field():
    """Image scale 1: on the bottom wall near an emitter 3 cm above it, E.n vanishes up to the images of the far
    walls (order 1); in free space it is the field's main part there."""
    near = ["scene.agents=[[20.0,3.0,0.0,1]]", "physics.image_scale=1"]

    def normal_fraction(walls: str) -> float:
        t = scene("eod_free", f"scene.walls={walls}", *near)
        wall = t[(t["element"] == "grid") & (t["y_cm"] == 0) & ((t["x_cm"] - 20).abs() <= 6)]
        return float((wall["ey_v_m"].abs() / np.hypot(wall["ex_v_m"], wall["ey_v_m"])).max())

    assert normal_fraction("true") < 2e-3
    assert normal_fraction("false") > 0.5


def test_objects_and_walls_distort_the_field_where_they_are():
    t = water(scene("eod_objects"))
    change = np.hypot(t["ex_v_m"], t["ey_v_m"]) / np.hypot(t["ex_free_v_m"], t["ey_free_v_m"])
    assert change.max() > 1.2 and change.min() < 0.8
    bodies = scene("eod_objects").query("element in ['emitter', 'agent', 'pellet']")
    assert sorted(bodies["element"]) == ["agent", "emitter", "pellet", "pellet", "pellet"]
    inside = t.assign(d=np.hypot(t["x_cm"] - 21.0, t["y_cm"] - 12.0))
    assert inside["d"].min() >= 1.0  # no water sample inside the silent fish


def test_sensing_ranges_match_spec_calibration():
    """Calibration (docs/model/sensors.md#calibration-checks): Knollenorgans hear a facing, emitting fish to about
    100 cm; Mormyromasts detect a pellet ahead to about 5 cm and a fish to about 10 cm."""
    t = build_scene(compose_scene("sensing_range", ["scene.range_points=48", "scene.bearings=8"]))
    grid = t[t["element"] == "grid"]
    assert set(map(tuple, grid[["variant", "receptor"]].drop_duplicates().to_numpy())) == {
        ("pellet", "mormyromast"), ("pellet", "ampullary"), ("agent", "mormyromast"), ("agent", "ampullary"),
        ("agent", "knollenorgan")}

    def reach(variant, receptor):
        ahead = grid[(grid["variant"] == variant) & (grid["receptor"] == receptor) & (grid["bearing_rad"] == 0)]
        return ahead.loc[ahead["ratio"] >= 1, "distance_cm"].max()

    assert 80 <= reach("agent", "knollenorgan") <= 120
    assert 4 <= reach("pellet", "mormyromast") <= 9
    assert 8 <= reach("agent", "mormyromast") <= 16
    overlap = grid[(grid["variant"] == "agent") & (grid["distance_cm"] < 2)]
    assert len(overlap) and overlap["ratio"].isna().all()  # two fish cannot overlap


def test_sensor_layout_has_every_sensor_on_the_body_circle():
    t = scene("sensor_layout")
    sensors = t[t["element"] == "sensor"]
    se = SensorsConfig()
    assert sensors.groupby("receptor").size().to_dict() == {
        "mormyromast": se.mormyromast.count, "ampullary": se.ampullary.count, "knollenorgan": se.knollenorgan.count}
    np.testing.assert_allclose(np.hypot(sensors["x_cm"] - 2.0, sensors["y_cm"] - 2.0), PH.agent_radius_cm)


def test_food_layouts_are_inside_their_arenas_and_reproducible():
    a, b = scene("food_layouts"), scene("food_layouts")
    pd.testing.assert_frame_equal(a, b)
    arenas = a[a["element"] == "arena"].set_index("variant")
    assert list(arenas.index) == ["training", "patchy", "uniform", "npatch"]
    assert tuple(arenas.loc["patchy", ["width_cm", "height_cm"]]) == (70.0, 70.0)
    pellets = a[a["element"] == "pellet"]
    assert len(pellets) > 0
    size = arenas.loc[pellets["variant"], ["width_cm", "height_cm"]].to_numpy()
    assert ((pellets[["x_cm", "y_cm"]].to_numpy() >= 0) & (pellets[["x_cm", "y_cm"]].to_numpy() <= size)).all()


def test_bad_scenes_fail_with_one_line():
    with pytest.raises(ValueError, match="outside"):
        scene("eod_free", "scene.agents=[[50.0,3.0,0.0,1]]")
    with pytest.raises(ConfigError, match="window_cm"):
        compose_scene("eod_free", ["scene.window_cm=[5,1,0,3]"])
    with pytest.raises(ConfigError, match="unknown scene"):
        compose_scene("nope")


def test_cli_writes_the_table_with_its_schema_config_and_provenance(tmp_path, capsys):
    assert main(["scene", "eod_walls", *COARSE, "--out", str(tmp_path)]) == 0
    assert pq.read_schema(tmp_path / "eod_walls.parquet").remove_metadata().equals(SCHEMA)
    assert (tmp_path / "config.yaml").is_file()
    prov = json.loads((tmp_path / "eod_walls.provenance.json").read_text())
    assert prov["scene"] == "eod_walls" and prov["scene_config"]["walls"] is True
    assert prov["overrides"] == COARSE
    assert main(["scene", "nope", "--out", str(tmp_path)]) == 2
    assert "unknown scene" in capsys.readouterr().err


def test_to_arrow_refuses_unknown_columns():
    with pytest.raises(ValueError, match="unexpected columns"):
        to_arrow(pd.DataFrame({"element": ["grid"], "bogus": [1.0]}))
