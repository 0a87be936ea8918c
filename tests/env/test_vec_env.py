"""VecEnv: kinematics, eating, biting, rewards, interventions, determinism, bad input."""

from __future__ import annotations

import numpy as np
import pytest

from efish.config import ConfigError, compose
from efish.env.observe import observation_slices

from ..helpers import BIG, actions
from ..helpers import make_env as make


def place_pellets(env, xy):
    env.state.alive[:] = False
    env.state.pellet_xy[0, : len(xy)] = xy
    env.state.alive[0, : len(xy)] = True


@pytest.mark.parametrize("size", [0.0, 0.4, 1.0])
def test_speed_and_turn_bounds_scale_with_size(size):
    env = make("env.n_agents=1", "arena=uniform70", "arena.layout=none", f"env.sizes=[{size}]",
               "env.starts=[[35,35,0.0]]")
    env.reset()
    env.step(actions(env, move=BIG, turn=BIG))
    w_max = 3.6 * 4 * (1 + size) / 83
    v_max = 0.35 * 2 * (1 + size) * 100 / 83
    assert env.state.heading[0, 0] == pytest.approx(w_max, rel=1e-12)
    np.testing.assert_allclose(env.state.xy[0, 0], [35 + v_max * np.cos(w_max), 35 + v_max * np.sin(w_max)], rtol=1e-12)
    assert v_max == pytest.approx(0.8434 * (1 + size), rel=1e-4)


def test_agents_never_overlap_nor_leave_a_small_arena():
    env = make("arena=collective", "arena.width_cm=12", "arena.height_cm=12", "env.episode_steps=100000",
               num_envs=4, seed=3)
    env.reset()
    rng = np.random.default_rng(0)
    for _ in range(300):
        a = np.concatenate([rng.normal(0, 3, (4, 4, 2)), rng.integers(0, 2, (4, 4, 2))], axis=-1)
        env.step(a)
        d = np.linalg.norm(env.state.xy[:, :, None] - env.state.xy[:, None], axis=-1) + 99 * np.eye(4)
        assert d.min() >= 2.0 - 1e-12
        assert env.state.xy.min() >= 1.0 and env.state.xy.max() <= 11.0


def test_an_agent_eats_exactly_the_pellet_in_its_cone_then_freezes_for_three_steps():
    env = make("env.n_agents=1", "arena=uniform70", "env.starts=[[10,10,0.0]]", "env.sizes=[0.5]")
    env.reset()
    place_pellets(env, [[11.5, 10.0], [10.0, 11.5], [12.5, 10.0]])  # ahead, beside (90 deg), ahead but 2.5 cm
    _, r, _, _, info = env.step(actions(env, move=-BIG))
    assert info["ate"][0, 0] and env.state.alive[0].tolist()[:3] == [False, True, True]
    assert info["reward_parts"]["food"][0, 0] == 10.0
    moved = []
    for _ in range(5):  # frozen on the 3 steps after eating, free on the 4th
        before = env.state.xy.copy()
        env.step(actions(env, move=BIG))
        moved.append(bool(np.any(env.state.xy != before)))
    assert moved == [False, False, False, True, True]


def test_bite_cooldown_is_five_steps_and_penalty_scales_with_size_difference():
    env = make("env.n_agents=2", "arena=uniform70", "arena.layout=none", "env.sizes=[0.9,0.2]",
               "env.starts=[[10,10,0.0],[12,10,3.14159]]")
    env.reset()
    bites = []
    for _ in range(8):
        a = actions(env, bite=0)
        a[0, 0, 3] = 1  # only agent 0 tries to bite, every step
        _, r, _, _, info = env.step(a)
        bites.append(bool(info["bit"][0, 0]))
        if bites[-1]:
            assert r[0, 1] == pytest.approx(-5 * (1 + 0.9 - 0.2))
            assert info["reward_parts"]["bite"][0, 0] == pytest.approx(-0.001)
    assert bites == [True, False, False, False, False, False, True, False]


def test_mutual_bites_are_simultaneous_and_both_count():
    env = make("env.n_agents=2", "arena=uniform70", "arena.layout=none", "env.sizes=[0.5,0.5]",
               "env.starts=[[10,10,0.0],[12,10,3.14159]]")
    env.reset()
    _, r, _, _, info = env.step(actions(env, bite=1))
    assert info["bit"][0].all() and info["was_bitten"][0].all()
    np.testing.assert_allclose(r[0], -5 * 1.0 - 0.001)


def test_shaping_sums_to_the_approach_over_the_perimeter():
    env = make("env.n_agents=1", "arena=uniform70", "env.starts=[[10,35,0.0]]", "env.sizes=[0.0]")
    env.reset()
    place_pellets(env, [[60.0, 35.0]])
    env.state.goal_dist[:] = 50.0
    total = 0.0
    for _ in range(20):
        _, r, _, _, info = env.step(actions(env, move=BIG))
        total += info["reward_parts"]["shaping"][0, 0]
    d_end = 60.0 - env.state.xy[0, 0, 0]
    assert total == pytest.approx((50.0 - d_end) / 280.0, rel=1e-9)


def test_no_reward_term_is_nan_without_food():
    env = make("arena=uniform70", "arena.layout=none", num_envs=2)
    env.reset()
    for _ in range(5):
        _, r, _, _, info = env.step(actions(env, move=BIG, eod=1, bite=1))
        assert all(np.all(np.isfinite(v)) for v in info["reward_parts"].values())


def test_muted_agent_never_emits_and_is_never_heard():
    env = make("env.muted=[0]", "arena=collective", num_envs=2)
    env.reset()
    sl = observation_slices(36, 24, 12, 4)
    for _ in range(10):
        obs, _, _, _, info = env.step(actions(env, eod=1))
        assert not info["eod"][:, 0].any() and info["eod"][:, 1:].all()
        slot0 = obs[:, 1:, sl["knollenorgan"]][..., :12]  # every other agent's slot 0 is agent 0
        assert np.all(slot0 == 0)


@pytest.mark.parametrize("receptor, block", [("mormyromast", "mormyromast"), ("ampullary", "ampullary"),
                                             ("knollenorgan", "knollenorgan")])
def test_an_ablated_receptor_block_is_all_zeros(receptor, block):
    env = make(f"sensors.{receptor}.enabled=false", "arena=collective", num_envs=2)
    env.reset()
    sl = observation_slices(36, 24, 12, 4)
    for _ in range(5):
        obs, *_ = env.step(actions(env, move=BIG, eod=1))
        assert np.all(obs[..., sl[block]] == 0)


def test_frozen_agent_never_moves():
    env = make("env.frozen=[1]", "arena=uniform70")
    env.reset()
    start = env.state.xy[0, 1].copy(), env.state.heading[0, 1]
    for _ in range(10):
        env.step(actions(env, move=BIG, turn=BIG))
    np.testing.assert_array_equal(env.state.xy[0, 1], start[0])
    assert env.state.heading[0, 1] == start[1]


def test_same_seed_same_bits_and_different_seeds_differ():
    def run(seed):
        env = make("env.episode_steps=20", num_envs=3, seed=seed)
        out = [env.reset()]
        rng = np.random.default_rng(7)
        for _ in range(30):
            a = np.concatenate([rng.normal(size=(3, 4, 2)), rng.integers(0, 2, (3, 4, 2))], -1)
            out.append(env.step(a)[0])
        return np.stack(out)
    a, b, c = run(1), run(1), run(2)
    np.testing.assert_array_equal(a, b)
    assert not np.array_equal(a, c)


def test_truncation_resets_and_keeps_the_final_observation():
    env = make("env.episode_steps=3", num_envs=2)
    env.reset()
    for _ in range(3):
        obs, _, term, trunc, info = env.step(actions(env))
    assert trunc.all() and not term.any() and "final_obs" in info
    assert (env.state.t == 0).all()


@pytest.mark.parametrize("override, key", [
    ("arena.layout=hexagonal", "arena.layout"),
    ("arena.uniform_density=-1", "arena.uniform_density"),
    ("env.n_agents=5", "env.n_agents"),
    ("env.muted=[9]", "env.muted"),
])
def test_bad_config_is_one_line_naming_the_key(override, key):
    with pytest.raises(ConfigError, match=key.replace(".", r"\.")) as err:
        compose([override])
    assert "\n" not in str(err.value)


def test_start_outside_the_arena_is_rejected():
    with pytest.raises(ValueError, match="env.starts"):
        make("env.n_agents=1", "env.starts=[[500,10,0.0]]").reset()


def test_wrong_action_shape_is_rejected():
    env = make(num_envs=2)
    env.reset()
    with pytest.raises(ValueError, match="actions must have shape"):
        env.step(np.zeros((2, 4, 3)))
