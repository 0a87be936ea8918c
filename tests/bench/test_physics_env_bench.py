"""``efish bench physics`` and ``efish bench env`` report what they promise on tiny sizes (never timing asserts)."""

from __future__ import annotations

from efish.bench.env import bench_env, format_env, scene_config
from efish.bench.physics import bench_physics, format_physics

from ..helpers import cfg_with


def test_physics_bench_reports_positive_rates_and_agrees_with_the_reference():
    r = bench_physics(cfg_with("bench.scenes=2", "bench.repeats=1", "bench.reference_scenes=1",
                               "bench.reference_rounds=1"))
    assert r["fast_agent_steps_per_s"] > 0 and r["reference_agent_steps_per_s"] > 0
    assert r["max_abs_diff_normalised"] <= 1e-6
    assert r["cpu"] and r["cpu_capability"]
    assert format_physics(r).splitlines()[0] == f"CPU: {r['cpu']} (torch CPU capability {r['cpu_capability']})"


def test_env_bench_has_a_row_per_scene_with_positive_rates():
    rows = bench_env(cfg_with("bench.reference_rounds=1"), num_envs=2, steps=3, reference_steps=1)
    assert len(rows) == 2
    for row in rows:
        assert all(v > 0 for k, v in row.items() if isinstance(v, float))
    assert "torch CPU capability" in format_env(rows).splitlines()[0]


def test_env_bench_sizes_are_config_fields():
    rows = bench_env(cfg_with("bench.reference_rounds=1", "bench.env_envs=1", "bench.env_steps=2"),
                     reference_steps=1)
    assert [r["num_envs"] for r in rows] == [1, 1]


def test_env_bench_scenes_keep_the_users_overrides():
    """Each scene sets its arena and agent count; a physics or sensor override of the command still applies."""
    cfg = cfg_with("physics.image_order=2", "sensors.knollenorgan.enabled=false")
    for arena, (layout, agents) in {"patchy70": ("patchy", 4), "onepatch": ("onepatch", 2)}.items():
        scene = scene_config(cfg, arena)
        assert (scene.arena.layout, scene.env.n_agents) == (layout, agents)
        assert scene.physics.image_order == 2 and not scene.sensors.knollenorgan.enabled
