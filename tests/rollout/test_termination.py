"""Rollout tables stop at each episode's end: homing arenas that end at different steps."""

from __future__ import annotations

import numpy as np

from efish.config import compose
from efish.rollout.run import run_episodes

from ..helpers import BIG


class WaitThenGo:
    """Arena b waits ``2 b`` steps, then swims straight ahead at full speed (a scripted, stateful policy)."""

    def initial_hidden(self, num_envs, n_agents):
        return np.zeros((num_envs, n_agents, 1), np.float32)

    def act(self, obs, hidden, starts, deterministic=True):
        b, n, _ = obs.shape
        waited = hidden[..., 0] >= 2 * np.arange(b)[:, None]
        actions = np.zeros((b, n, 4))
        actions[..., 0] = np.where(waited, BIG, -BIG)
        return actions, hidden + 1


def homing_tables(episodes=4):
    # the homer starts 8 cm from the target and faces it: it is home two steps after it starts to swim
    cfg = compose(["assay=homing", "env.starts=[[35,35,0.0],[43,35,3.14159265]]", "env.episode_steps=60"])
    return run_episodes(cfg, WaitThenGo(), episodes, condition="electric", seed=0)


def test_no_rows_after_an_episode_ends_and_steps_count_up_to_it():
    t = homing_tables()
    steps, episodes = t["steps"], t["episodes"]
    last = steps.groupby("episode")["t"].max()
    assert last.nunique() == len(last)  # every arena ended at a different step
    np.testing.assert_array_equal(np.diff(last.to_numpy()), 2)  # two steps later per arena waited longer
    ends = steps[steps["terminated"]]
    assert (ends.groupby("episode")["t"].max() == last).all()  # the last row of each episode is its end
    assert ends["success"].all()
    homer = episodes[episodes["agent"] == 1].set_index("episode")
    np.testing.assert_array_equal(homer["steps"], last + 1)
    assert homer["success"].all() and homer["terminated"].all()
    returns = steps[steps["agent"] == 1].groupby("episode")["reward"].sum()
    np.testing.assert_allclose(homer["return"], returns, rtol=1e-5)


def test_time_limit_ends_every_arena_at_the_same_step_without_termination():
    cfg = compose(["env.episode_steps=7", "scale=smoke"])
    t = run_episodes(cfg, WaitThenGo(), 2, seed=0)
    assert (t["steps"].groupby("episode")["t"].max() == 6).all()
    assert not t["steps"]["terminated"].any() and not t["episodes"]["success"].any()
    assert (t["episodes"]["steps"] == 7).all()
