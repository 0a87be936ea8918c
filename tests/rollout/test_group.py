"""Grouped rollouts: each policy of a group gets the tables it would get alone, whichever policies share its group."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest
import torch

from efish.config import compose
from efish.env.observe import observation_size
from efish.rl.networks import Actor
from efish.rl.policy import Policy
from efish.rollout.group import run_group
from efish.rollout.run import run_episodes

from ..helpers import BIG


class WaitThenGo:
    """Arena b waits ``wait * b`` steps, then swims straight ahead: its episodes end at different steps."""

    def __init__(self, wait: int):
        self.wait = wait

    def initial_hidden(self, num_envs, n_agents):
        return np.zeros((num_envs, n_agents, 1), np.float32)

    def act(self, obs, hidden, starts, deterministic=True):
        b, n, _ = obs.shape
        actions = np.zeros((b, n, 4))
        actions[..., 0] = np.where(hidden[..., 0] >= self.wait * np.arange(b)[:, None], BIG, -BIG)
        return actions, hidden + 1


def network(cfg, seed: int, hidden: int = 8) -> Policy:
    """An untrained actor of its own seed: deterministic actions that depend on what it observes."""
    torch.manual_seed(seed)
    return Policy(Actor(observation_size(cfg), hidden), cfg.env.n_agents)


def assert_same_tables(alone: dict[str, pd.DataFrame], grouped: dict[str, pd.DataFrame]) -> None:
    assert alone.keys() == grouped.keys()
    for name in alone:
        pd.testing.assert_frame_equal(alone[name], grouped[name], check_exact=True, obj=name)


def test_each_network_gets_its_tables_alone():
    cfg = compose(["scale=smoke", "assay=patchy4", "env.episode_steps=40"])
    policies = [network(cfg, seed) for seed in (1, 2, 3)]
    grouped = run_group(cfg, policies, 3, condition="control", seed=5, record_hidden=True)
    for policy, tables in zip(policies, grouped, strict=True):
        assert_same_tables(run_episodes(cfg, policy, 3, condition="control", seed=5, record_hidden=True), tables)
    # the policies differ, so their tables do: the split is not a copy of one member
    assert not grouped[0]["steps"]["x_cm"].equals(grouped[1]["steps"]["x_cm"])


def test_episodes_that_end_at_different_steps_in_each_member():
    # the homer starts 8 cm from the target and faces it; each arena waits longer, and each policy waits longer
    cfg = compose(["assay=homing", "env.starts=[[35,35,0.0],[43,35,3.14159265]]", "env.episode_steps=60"])
    policies = [WaitThenGo(3), WaitThenGo(1), WaitThenGo(2)]
    grouped = run_group(cfg, policies, 4, condition="electric", seed=0)
    for policy, tables in zip(policies, grouped, strict=True):
        assert_same_tables(run_episodes(cfg, policy, 4, condition="electric", seed=0), tables)
    last = [g["steps"]["t"].max() for g in grouped]
    assert len(set(last)) == 3  # the members ended at different steps


def test_a_policys_tables_do_not_depend_on_its_companions():
    cfg = compose(["scale=smoke", "assay=wide2", "env.episode_steps=30"])
    a, b, c = (network(cfg, seed) for seed in (4, 5, 6))
    first = run_group(cfg, [a, b], 2, seed=9)[0]
    second = run_group(cfg, [c, b, a], 2, seed=9)[2]
    assert_same_tables(first, second)


def test_bad_groups_are_one_clear_error():
    cfg = compose(["scale=smoke", "env.episode_steps=5"])
    with pytest.raises(ValueError, match="deterministic"):
        run_group(cfg, [network(cfg, 1)], 2, deterministic=False)
    with pytest.raises(ValueError, match="one hidden size"):
        run_group(cfg, [network(cfg, 1, hidden=8), network(cfg, 2, hidden=4)], 2)
    with pytest.raises(ValueError, match="at least one"):
        run_group(cfg, [], 2)


@pytest.mark.parametrize("assay", ["patchy4", "homing"])
def test_a_grouped_assay_gives_each_member_its_run_alone(assay):
    """patchy4 acts with the members' own policies (one env for both), homing with the shared recipe policies (one
    run, the same tables for both)."""
    from efish.rollout.assay import run_assay, run_assay_group

    overrides = [f"assay={assay}", "scale=smoke", "scale.max_episode_steps=15", "scale.max_episodes=2"]
    cfg = compose(overrides)
    shared = {"homing": network(compose(["assay=homing"]), 7),
              "homing_raycast": network(compose(["assay=homing", "sensors.perception=raycast"]), 8)}
    members = [{"selected": network(cfg, seed)} for seed in (1, 2)]
    grouped, stats = run_assay_group(overrides, shared, members)
    for member, tables in zip(members, grouped, strict=True):
        assert_same_tables(run_assay(overrides, {**shared, **member})[0], tables)
    assert stats["env_steps"] > 0
    with pytest.raises(ValueError, match="same policies"):
        run_assay_group(overrides, shared, [{"selected": members[0]["selected"]}, {}])
