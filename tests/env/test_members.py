"""VecEnv members: K seeds' arenas in one env, each stepping exactly as its own VecEnv would."""

from __future__ import annotations

import pickle

import numpy as np
import pytest

from efish.config import compose
from efish.env import VecEnv

# the training arenas (sampled per episode, so members need different pellet capacities), the one-patch arena with
# regrowth and a bot (arena generators drawn during steps), and a homing task
CONFIGS = {
    "training arenas": ["policy=foraging", "env.episode_steps=25"],
    "one patch with a bot": ["assay=bot", "env.sizes=[0.5,0.5]", "env.bot_eod_rate=0.5", "env.episode_steps=25"],
    "homing": ["policy=homing", "env.episode_steps=25"],
}


def random_actions(rng: np.random.Generator, b: int, n: int) -> np.ndarray:
    return np.concatenate([rng.normal(0, 2, (b, n, 2)), rng.integers(0, 2, (b, n, 2))], axis=-1)


def trajectories(env: VecEnv, actions: list[np.ndarray]) -> list[dict[str, np.ndarray]]:
    """Observations, rewards, ends, positions and pellets of every step (autoreset on: episodes end and restart)."""
    out = [{"obs": env.reset()}]
    for a in actions:
        obs, reward, term, trunc, _ = env.step(a)
        s = env.state
        out.append({"obs": obs, "reward": reward, "terminated": term, "truncated": trunc, "xy": s.xy.copy(),
                    "pellet_xy": s.pellet_xy.copy(), "pellet_phi": s.pellet_phi.copy(), "alive": s.alive.copy()})
    return out


def assert_member_equals(solo: list[dict], together: list[dict], rows: slice, k: int) -> None:
    """Member ``k`` (``rows`` of the group's arrays) equals its env alone, step by step; pellet slots beyond its own
    are those another member needed, never alive in its arenas."""
    for t, (mine, theirs) in enumerate(zip(solo, together, strict=True)):
        for key, x in mine.items():
            y = theirs[key][rows]
            if key.startswith("pellet") or key == "alive":
                assert not theirs["alive"][rows][:, x.shape[1]:].any()
                y = y[:, : x.shape[1]]
            np.testing.assert_array_equal(x, y, err_msg=f"member {k}, step {t}, {key}")


@pytest.mark.parametrize("name", list(CONFIGS))
def test_each_member_steps_exactly_as_its_own_env(name):
    cfg = compose(CONFIGS[name])
    seeds, b = [11, 3, 11], 2  # a seed twice: two members with the same episodes stay bit-identical
    group = VecEnv(cfg, num_envs=b, seed=seeds)
    rng = np.random.default_rng(0)
    actions = [random_actions(rng, b * len(seeds), cfg.env.n_agents) for _ in range(60)]
    together = trajectories(group, actions)
    for k, seed in enumerate(seeds):
        rows = group.member_slice(k)
        solo = trajectories(VecEnv(cfg, num_envs=b, seed=seed), [a[rows] for a in actions])
        assert_member_equals(solo, together, rows, k)


def test_a_member_does_not_depend_on_its_companions():
    cfg = compose(CONFIGS["training arenas"])
    rng = np.random.default_rng(1)
    actions = [random_actions(rng, 2, cfg.env.n_agents) for _ in range(40)]
    first = VecEnv(cfg, num_envs=2, seed=[5, 8])
    second = VecEnv(cfg, num_envs=2, seed=[9, 1, 5])
    a = trajectories(first, [np.concatenate([x, x]) for x in actions])
    b = trajectories(second, [np.concatenate([x, x, x]) for x in actions])
    for mine, theirs in zip(a, b, strict=True):
        np.testing.assert_array_equal(mine["obs"][first.member_slice(0)], theirs["obs"][second.member_slice(2)])


def test_members_make_a_batch_of_their_arenas():
    env = VecEnv(compose([]), num_envs=3, seed=[1, 2])
    assert env.num_envs == 6 and env.members == 2
    assert env.reset().shape[0] == 6
    assert [env.member_of(b) for b in range(6)] == [0, 0, 0, 1, 1, 1]
    with pytest.raises(ValueError, match="non-empty"):
        VecEnv(compose([]), num_envs=3, seed=[])


def test_a_state_saved_before_members_restores_as_one_member():
    env = VecEnv(compose(["env.episode_steps=25"]), num_envs=2, seed=4)
    env.reset()
    state = env.state_dict()["state"]
    old = dict(vars(state))  # the state as pickled before members: one batch-wide noise generator
    old["noise_rng"] = old.pop("noise_rngs")[0]
    del old["capacity"]
    restored = pickle.loads(pickle.dumps(state))  # noqa: S301 - our own object
    restored.__setstate__(old)
    assert len(restored.noise_rngs) == 1 and restored.capacity.tolist() == [state.alive.shape[1]]
