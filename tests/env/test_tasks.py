"""Bot, homing and ray-casting baselines (docs/model/environment.md#rewards, docs/methods/assays.md)."""

from __future__ import annotations

import numpy as np
import pytest
from scipy import stats

from efish.env.observe import ray_observation_slices
from efish.env.raycast import KIND_AGENT, KIND_FOOD, KIND_NONE, KIND_WALL, cast_rays

from ..helpers import BIG, actions
from ..helpers import make_env as make


def test_bot_stays_within_its_bound_and_emits_at_its_rate():
    env = make("arena=onepatch", "env.n_agents=2", "env.bots=[0]", "env.bot_eod_rate=0.25",
               "env.starts=[[75,75,0.0],[20,20,0.0]]", "env.episode_steps=100000", num_envs=4, seed=1)
    env.reset()
    emitted, steps = 0, 600
    v_max = env.v_max()[:, 0].max()
    for _ in range(steps):
        _, _, _, _, info = env.step(actions(env, move=BIG, eod=1, bite=1))
        d = np.linalg.norm(env.state.xy[:, 0] - 75.0, axis=-1)
        assert d.max() <= 8.5 + v_max
        assert not info["bit"][:, 0].any() and not info["ate"][:, 0].any()
        emitted += int(info["eod"][:, 0].sum())
    assert stats.binomtest(emitted, steps * 4, 0.25).pvalue > 1e-4


def test_homing_rewards_termination_and_target():
    env = make("env=homing", "arena=uniform70", "arena.layout=none", "env.starts=[[35,35,0.0],[41,35,3.14159]]")
    env.reset()
    rewards, done_at = [], None
    for k in range(12):
        _, r, term, trunc, info = env.step(actions(env, move=BIG, eod=0, bite=1))
        assert info["eod"][0, 0] and not info["bit"].any()  # target always emits; no biting in homing
        rewards.append(r[0].copy())
        if term[0]:
            done_at = k
            break
    assert rewards[0][0] == 0.0  # the target earns nothing
    # the homer starts 6 cm away, moves towards the target and is home (< 4 cm) from its first or second step
    home = [k for k, r in enumerate(rewards) if r[1] > 5]
    assert done_at is not None and done_at == home[0] + 4  # 5 consecutive steps at home end the episode
    assert rewards[done_at][1] == pytest.approx(10 - 0.05 + 0.01 * 0 / 280, abs=0.01)


def test_rays_see_walls_food_and_agents_at_the_right_distance():
    xy = np.array([[[10.0, 10.0], [30.0, 10.0]]])
    heading = np.zeros((1, 2))
    pellets = np.array([[[10.0, 20.0]]])
    angles = np.array([0.0, np.pi / 2, np.pi, -np.pi / 2])
    prox, kind = np.zeros((1, 2, 4)), np.zeros((1, 2, 4))
    cast_rays(xy, heading, pellets, np.array([[True]]), np.array([50.0]), np.array([50.0]), angles, 100.0, 1.0, 0.25,
              prox, kind)
    np.testing.assert_allclose(prox[0, 0], [1 - 19 / 100, 1 - 9.75 / 100, 1 - 10 / 100, 1 - 10 / 100])
    np.testing.assert_array_equal(kind[0, 0], [KIND_AGENT, KIND_FOOD, KIND_WALL, KIND_WALL])
    prox_short, kind_short = np.zeros((1, 2, 4)), np.zeros((1, 2, 4))
    cast_rays(xy, heading, pellets, np.array([[False]]), np.array([50.0]), np.array([50.0]), angles, 5.0, 1.0, 0.25,
              prox_short, kind_short)
    assert np.all(kind_short[0, 0] == KIND_NONE) and np.all(prox_short[0, 0] == 0)


def test_ray_casting_replaces_every_electric_block():
    env = make("sensors.perception=raycast", "arena=collective", num_envs=2)
    obs = env.reset()
    sl = ray_observation_slices(36)
    assert obs.shape == (2, 4, sl["reserved"].stop) == (2, 4, 83)
    assert np.all((obs[..., sl["ray_kind"]] >= 0) & (obs[..., sl["ray_kind"]] <= 1))
    assert np.any(obs[..., sl["ray_kind"]] == KIND_WALL)
