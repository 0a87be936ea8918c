"""The effect plan: which effects run, and that switched-off effects read exactly 0."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest

from efish import Snapshot, sense
from efish.env.vec_env import scene_of
from efish.physics import Scene, build_plan
from efish.sensors.sense import sense_batch

from ..helpers import RECEPTORS, cfg_with, random_snapshot


@pytest.fixture(scope="module")
def busy_scene() -> Snapshot:
    """Everything present: emitters, silent agents, pellets close by."""
    return Snapshot(agent_xy=[[20, 20], [25, 21], [22, 25], [40, 40]], agent_heading=[0.0, 2.0, -1.0, 0.5],
                    agent_size=[0.1, 0.5, 0.9, 0.3], agent_emitting=[True, True, False, True],
                    pellet_xy=[[22, 20], [24, 23], [21, 22]], pellet_orientation=[0.0, 1.0, 2.0],
                    width=70, height=70)


def test_default_plan_runs_every_effect(default_cfg):
    plan = build_plan(default_cfg)
    for name in ("fields", "mormyromast", "ampullary", "knollenorgan", "eod_emission", "induction",
                 "self_part", "cons_part", "intrinsic_fields", "pellets", "wall_images", "noise", "culling"):
        assert plan.on(name), name
    assert not plan.on("wall_distortion")  # default off (docs/model/sensors.md#mormyromasts)
    with pytest.raises(KeyError, match="no_such_effect"):
        plan.on("no_such_effect")


def test_busy_scene_reads_something_everywhere(default_cfg, busy_scene):
    # the scene the ablations below start from has non-zero readings of every class
    r = sense(busy_scene, default_cfg)
    for name in RECEPTORS:
        assert np.any(r[name] != 0), name


def test_no_pellets_turns_the_pellet_effect_off(default_cfg):
    assert not build_plan(default_cfg, Scene(pellets=False)).on("pellets")
    assert build_plan(default_cfg, Scene(pellets=True)).on("pellets")
    assert not build_plan(default_cfg, scene_of(cfg_with("arena.layout=none"))).on("pellets")  # the env's scene


def test_pellets_absent_from_the_scene_are_not_sensed(busy_scene):
    cfg = cfg_with("arena.layout=none", "physics.image_order=0")
    plan = build_plan(cfg, scene_of(cfg))
    without = sense(replace(busy_scene, pellet_xy=np.zeros((0, 2)), pellet_orientation=np.zeros(0)), cfg)
    ignored = sense_batch(busy_scene.as_batch(), plan)
    for name in RECEPTORS:
        np.testing.assert_array_equal(ignored[name][0], without[name])


def test_emitters_none_turns_induction_and_knollenorgan_off(busy_scene):
    cfg = cfg_with("env.muted=[0,1,2,3]")
    plan = build_plan(cfg, scene_of(cfg))  # every agent muted: the env's scene has no emitter
    assert not plan.on("eod_emission")
    assert not plan.on("induction")
    assert not plan.on("knollenorgan")
    assert plan.on("ampullary")  # intrinsic fields need no emitter
    r = {k: v[0] for k, v in sense_batch(busy_scene.as_batch(), plan).items()}
    for name in ("mormyromast", "knollenorgan", "knollen_size"):
        assert np.all(r[name] == 0), name
    assert np.any(r["ampullary"] != 0)


def test_the_homing_target_makes_a_muted_scene_emit():
    cfg = cfg_with("env=homing", "env.muted=[0,1]")
    assert scene_of(cfg).emitters and build_plan(cfg, scene_of(cfg)).on("eod_emission")


def test_nobody_emitting_in_the_snapshot_gives_the_same_as_muted(default_cfg, busy_scene):
    silent = replace(busy_scene, agent_emitting=np.zeros(4, dtype=bool))
    plan = build_plan(default_cfg, Scene.of_batch(silent.as_batch()))
    assert not plan.on("induction") and not plan.on("knollenorgan")
    r = sense(silent, default_cfg)
    for name in ("mormyromast", "knollenorgan", "knollen_size"):
        assert np.all(r[name] == 0), name


def test_knollenorgan_disabled_reads_all_zero(busy_scene):
    cfg = cfg_with("sensors.knollenorgan.enabled=false")
    plan = build_plan(cfg)
    assert not plan.on("knollenorgan")
    assert "sensors.knollenorgan.enabled" in plan.explain()
    for reference in (False, True):
        r = sense(busy_scene, cfg, reference=reference, rng=np.random.default_rng(0))
        assert r["knollenorgan"].shape == (4, 3, 12)
        assert np.all(r["knollenorgan"] == 0) and np.all(r["knollen_size"] == 0)
        assert np.any(r["mormyromast"] != 0) and np.any(r["ampullary"] != 0)


@pytest.mark.parametrize("name", ["mormyromast", "ampullary"])
def test_other_ablations_read_all_zero(busy_scene, name):
    cfg = cfg_with(f"sensors.{name}.enabled=false")
    assert not build_plan(cfg).on(name)
    for reference in (False, True):
        r = sense(busy_scene, cfg, reference=reference)
        assert np.all(r[name] == 0)
        assert np.any(r["knollenorgan"] != 0)


def test_raycast_perception_computes_no_fields(busy_scene):
    cfg = cfg_with("sensors.perception=raycast")
    plan = build_plan(cfg)
    assert not plan.on("fields")
    for name in ("mormyromast", "ampullary", "knollenorgan", "induction", "intrinsic_fields", "wall_images"):
        assert not plan.on(name), name
    for reference in (False, True):
        r = sense(busy_scene, cfg, reference=reference, rng=np.random.default_rng(1), return_raw=True)
        for name in RECEPTORS + ("mormyromast_raw", "ampullary_raw", "knollenorgan_raw"):
            assert np.all(r[name] == 0), name


def test_physics_switches_remove_their_sources(busy_scene):
    r = sense(busy_scene, cfg_with("physics.intrinsic=false"))
    assert np.all(r["ampullary"] == 0) and np.any(r["mormyromast"] != 0)
    r = sense(busy_scene, cfg_with("physics.induction=false"))
    assert np.all(r["mormyromast"] == 0) and np.any(r["ampullary"] != 0)
    # without induction the wall-distortion switch alone still feeds the emitters' Mormyromasts
    r = sense(busy_scene, cfg_with("physics.induction=false", "sensors.mormyromast.wall_distortion=true"))
    assert np.all(r["mormyromast"][2] == 0)  # agent 2 is silent
    assert np.all(r["mormyromast"][[0, 1, 3]] != 0)
    r = sense(busy_scene, cfg_with("physics.emission=false"))
    assert np.all(r["mormyromast"] == 0) and np.all(r["knollenorgan"] == 0)


def test_closed_gates_turn_induction_off():
    plan = build_plan(cfg_with("sensors.mormyromast.g_self=0", "sensors.mormyromast.g_cons=0"))
    assert not plan.on("induction")
    assert "gates" in next(e.why for e in plan.effects if e.name == "induction")


def test_single_agent_scene_has_no_conspecific_effects():
    plan = build_plan(cfg_with(), Scene(agents=1))
    assert not plan.on("knollenorgan") and not plan.on("cons_part")


def test_wall_images_follow_the_image_order(default_cfg):
    assert len(build_plan(cfg_with("physics.image_order=0")).image_weights) == 1
    assert not build_plan(cfg_with("physics.image_order=0")).on("wall_images")
    assert not build_plan(cfg_with("physics.image_scale=0")).on("wall_images")
    plan = build_plan(cfg_with("physics.image_order=2"))
    assert len(plan.image_weights) == 13
    np.testing.assert_allclose(sorted(set(np.round(plan.image_weights, 12))), [0.95**2, 0.95, 1.0])


def test_tolerance_zero_turns_culling_off(default_cfg):
    assert not build_plan(default_cfg, tolerance=0.0).on("culling")
    assert build_plan(default_cfg).tolerance == default_cfg.physics.tolerance
    with pytest.raises(ValueError, match="tolerance"):
        build_plan(default_cfg, tolerance=-1.0)


def test_plan_constants_in_si_units(default_cfg):
    plan = build_plan(default_cfg)
    assert plan.eod_half_separation == pytest.approx(0.005)
    assert plan.sensor_radius == pytest.approx(0.01)
    # induced moment per field: 4 pi eps0 R^3 chi (docs/model/physics.md#induction)
    eps0 = default_cfg.physics.eps0
    assert plan.alpha_agent == pytest.approx(4 * np.pi * eps0 * 0.01**3 * -0.5, rel=1e-12)
    assert plan.alpha_pellet == pytest.approx(4 * np.pi * eps0 * 0.0025**3 * -0.5, rel=1e-12)
    assert plan.softening2 == pytest.approx(1e-10)
    assert plan.dtype == "float64"
    assert build_plan(default_cfg, dtype="float32").dtype == "float32"


def test_explain_mentions_every_effect(default_cfg):
    for cfg in (default_cfg, cfg_with("sensors.perception=raycast"), cfg_with("env.muted=[0,1,2,3]")):
        plan = build_plan(cfg, tolerance=0.0)
        text = plan.explain()
        assert "tolerance 0" in text
        for e in plan.effects:
            assert e.name in text and e.why in text
            line = next(ln for ln in text.splitlines() if f"] {e.name} " in ln + " ")
            assert line.lstrip().startswith("[x]" if e.on else "[ ]"), line


def test_noise_is_seeded_and_bounded(default_cfg, busy_scene):
    plain = sense(busy_scene, default_cfg, return_raw=True)
    a = sense(busy_scene, default_cfg, rng=np.random.default_rng(7))
    b = sense(busy_scene, default_cfg, rng=np.random.default_rng(7))
    c = sense(busy_scene, default_cfg, rng=np.random.default_rng(8))
    for name in RECEPTORS:
        np.testing.assert_array_equal(a[name], b[name])
    assert not np.array_equal(a["mormyromast"], c["mormyromast"])
    # U(0.95, 1.05) moves a log-normalised Mormyromast reading (6 decades) by at most -log10(0.95) / 6
    moved = np.abs(a["mormyromast"] - plain["mormyromast"])
    assert 0 < moved.max() <= -np.log10(0.95) / 6 + 1e-12
    assert np.all(np.sign(a["mormyromast"]) * np.sign(plain["mormyromast"]) >= 0)  # never flips a sign
    cfg_quiet = cfg_with("sensors.noise.enabled=false")
    q = sense(busy_scene, cfg_quiet, rng=np.random.default_rng(7))
    for name in RECEPTORS:
        np.testing.assert_array_equal(q[name], plain[name])


def test_ampullary_interference_while_a_conspecific_emits(default_cfg):
    # U(0, 2) on Ampullary readings when any *other* agent emits: much larger spread
    s = random_snapshot(np.random.default_rng(3), 2, 60, emitting=np.array([False, True]))
    plain = sense(s, default_cfg, return_raw=True)
    from efish.physics.readings import RawReadings
    from efish.sensors.noise import apply_noise
    raw = RawReadings(plain["mormyromast_raw"][None], plain["ampullary_raw"][None], plain["knollenorgan_raw"][None])
    plan = build_plan(default_cfg)
    noisy = apply_noise(raw, s.agent_emitting[None], plan, np.random.default_rng(0))
    nz = raw.ampullary != 0
    ratio = noisy.ampullary[nz] / raw.ampullary[nz]
    agent = np.broadcast_to(np.arange(2)[None, :, None], raw.ampullary.shape)[nz]
    assert np.all((ratio[agent == 0] >= 0) & (ratio[agent == 0] <= 2)) and ratio[agent == 0].std() > 0.3
    assert np.all((ratio[agent == 1] >= 0.95) & (ratio[agent == 1] <= 1.05))  # its only conspecific is silent
    m = noisy.mormyromast[raw.mormyromast != 0] / raw.mormyromast[raw.mormyromast != 0]
    assert np.all((m >= 0.95) & (m <= 1.05))
