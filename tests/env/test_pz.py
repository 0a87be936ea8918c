"""The PettingZoo adapter: PettingZoo's own API and state tests, the global state, rendering, seeding."""

from __future__ import annotations

import warnings

import numpy as np
import pytest
from matplotlib.colors import to_rgb
from pettingzoo.test import collect_render_results, parallel_api_test, state_test
from pettingzoo.utils.conversions import parallel_to_aec

from efish.drawing import agent_colour
from efish.env import parallel_env
from efish.env.pz import EfishParallelEnv

from ..helpers import BIG, cfg_with

SHORT = {"env.episode_steps": 25}


def actions(env: EfishParallelEnv, move: float = 0.0, eod: int = 0) -> dict:
    """The same action for every live agent: raw move ``move``, no turn, EOD ``eod``, no bite."""
    return {a: {"move_turn": np.array([move, 0.0]), "eod_bite": np.array([eod, 0])} for a in env.agents}


def stacked(obs: dict, env: EfishParallelEnv) -> np.ndarray:
    """The agents' observations concatenated in id order: what ``state()`` must be."""
    return np.concatenate([obs[a] for a in env.possible_agents])


def test_passes_the_pettingzoo_parallel_api_test():
    parallel_api_test(parallel_env(**SHORT), num_cycles=60)


def test_passes_the_pettingzoo_state_test_through_the_aec_conversion():
    # state_test steps an AEC env, so the parallel env runs through PettingZoo's own conversion; 30 cycles of
    # 4 agents run past the end of a 25-step episode, where state() must still lie in the state space
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        state_test(parallel_to_aec(parallel_env(**SHORT)), parallel_env(**SHORT), num_cycles=30)
    assert not [w for w in caught if "state" in str(w.message).lower()], [str(w.message) for w in caught]


def test_state_is_every_observation_in_id_order_before_and_after_the_end():
    env = parallel_env(**{"env.episode_steps": 3})
    with pytest.raises(RuntimeError, match="before reset"):
        env.state()
    obs, _ = env.reset(seed=2)
    assert np.array_equal(env.state(), stacked(obs, env))
    for _ in range(3):
        obs = env.step(actions(env, move=1.0, eod=1))[0]
        state = env.state()
        assert state.dtype == np.float32 and env.state_space.contains(state)
        assert np.array_equal(state, stacked(obs, env))
    assert env.agents == [] and np.array_equal(env.state(), stacked(obs, env))  # the state the episode ended in


def test_state_is_agent_zeros_row_of_the_critic_input():
    from efish.rl.collect import agent_centric_state

    env = parallel_env(**SHORT)
    obs, _ = env.reset(seed=0)
    batch = np.stack([obs[a] for a in env.possible_agents])[None]
    assert np.array_equal(env.state(), agent_centric_state(batch)[0, 0])


@pytest.mark.parametrize("perception", ["electric", "raycast"])
def test_observations_stay_in_the_declared_bounds(perception):
    env = parallel_env(**SHORT, **{"sensors.perception": perception})
    obs, _ = env.reset(seed=1)
    rng = np.random.default_rng(0)
    for _ in range(25):
        acts = {a: {"move_turn": rng.normal(0.0, 5.0, 2), "eod_bite": rng.integers(0, 2, 2)} for a in env.agents}
        obs = env.step(acts)[0]
        for a in env.possible_agents:
            assert env.observation_space(a).contains(obs[a]), (a, obs[a].min(), obs[a].max())


def fish_column(frame: np.ndarray, agent: int = 0) -> float:
    """Mean column of the pixels in ``agent``'s colour (its body, and its legend marker, which stays put)."""
    colour = np.round(np.array(to_rgb(agent_colour(agent))) * 255)
    return float(np.argwhere((np.abs(frame - colour) <= 2).all(axis=-1))[:, 1].mean())


def test_render_draws_the_arena_and_follows_the_fish():
    env = parallel_env(render_mode="rgb_array", **{"env.n_agents": 1, "arena": "uniform70", "arena.layout": "none",
                                                   "env.sizes": [0.5], "env.starts": [[15, 35, 0.0]]})
    env.reset(seed=0)
    before = env.render()
    assert before.dtype == np.uint8 and before.ndim == 3 and before.shape[2] == 3
    for _ in range(10):
        env.step(actions(env, move=BIG))  # heading 0: straight along +x, about 13 cm
    after = env.render()
    assert after.shape == before.shape and not np.array_equal(after, before)
    assert fish_column(after) > fish_column(before) + 10


def test_render_passes_pettingzoos_rgb_array_checks():
    env = parallel_to_aec(parallel_env(render_mode="rgb_array", **SHORT))
    for frame in collect_render_results(env):
        assert isinstance(frame, np.ndarray) and frame.dtype == np.uint8 and frame.ndim == 3 and frame.shape[2] == 3


def test_render_modes_none_and_unknown():
    assert EfishParallelEnv.metadata["render_modes"] == ["rgb_array"]
    env = parallel_env(**SHORT)
    env.reset(seed=0)
    with pytest.warns(UserWarning, match="render_mode='rgb_array'"):
        assert env.render() is None
    with pytest.raises(ValueError, match="unknown render_mode 'human'"):
        EfishParallelEnv(cfg_with(), render_mode="human")
    with pytest.raises(RuntimeError, match="before reset"):
        parallel_env(render_mode="rgb_array", **SHORT).render()


def run_seeded(seed: int) -> tuple[list[np.ndarray], np.ndarray]:
    """States of 5 steps with EODs of a fresh rendering env reset with ``seed``, and its last frame."""
    env = parallel_env(render_mode="rgb_array", **SHORT)
    env.reset(seed=seed)
    states = []
    for _ in range(5):
        env.step(actions(env, move=1.0, eod=1))
        states.append(env.state())
    return states, env.render()


def test_a_seeded_env_reproduces_its_states_and_frames():
    (states, frame), (again, frame_again) = run_seeded(7), run_seeded(7)
    assert all(np.array_equal(a, b) for a, b in zip(states, again, strict=True))
    assert np.array_equal(frame, frame_again)
    assert not np.array_equal(states[-1], run_seeded(8)[0][-1])
