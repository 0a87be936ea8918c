"""A rollout whose critic runs once over all steps gives what stepping the critic with the env gives."""

from __future__ import annotations

import numpy as np
import pytest
import torch

from efish.config import compose
from efish.env.vec_env import VecEnv
from efish.rl.advantages import gae
from efish.rl.collect import agent_centric_state, collect, initial_carry
from efish.rl.train import Learner

# Episodes of 7 steps in rollouts of 20: truncations inside the rollout and inside chunks of 5.
SMALL = ["arena=uniform70", "arena.width_cm=30", "arena.height_cm=30", "env.episode_steps=7", "train.hidden=16",
         "train.num_envs=3", "train.rollout_steps=20", "train.chunk=5"]


def stepped_rollout(cfg, env, learner, carry, generator):
    """The reference: actor and critic stepped together, every value, log-probability and bootstrap computed at
    its step, as the rollout did before the critic's single pass."""
    t_cfg = cfg.train
    T, L, B, N = t_cfg.rollout_steps, t_cfg.chunk, env.num_envs, env.n
    S = B * N
    obs_np, h_a, h_c, starts = carry["obs"], carry["h_actor"], carry["h_critic"], carry["starts"]
    out = {k: [] for k in ("values", "logp", "rewards", "terminated", "truncated", "next_values", "h_critic")}
    with torch.no_grad():
        for t in range(T):
            if t % L == 0:
                out["h_critic"].append(h_c)
            state = torch.as_tensor(agent_centric_state(obs_np).reshape(1, S, -1))
            dist, h_a, _ = learner.actor(torch.as_tensor(obs_np.reshape(1, S, -1)), h_a, starts[None])
            values, h_c = learner.critic(state, h_c, starts[None])
            actions = dist.sample(generator)
            obs_np, reward, term, trunc, info = env.step(actions.reshape(B, N, 4).numpy())
            next_values = torch.zeros(S)
            if trunc.any():
                final = torch.as_tensor(agent_centric_state(info["final_obs"]).reshape(1, S, -1))
                nv, _ = learner.critic(final, h_c, torch.zeros(1, S))
                next_values = learner.value_norm.denormalize(nv[0])
            for k, v in (("values", values[0]), ("logp", dist.log_prob(actions)[0]),
                         ("rewards", torch.as_tensor(reward.reshape(S), dtype=torch.float32)),
                         ("terminated", torch.as_tensor(np.repeat(term, N))),
                         ("truncated", torch.as_tensor(np.repeat(trunc, N))), ("next_values", next_values)):
                out[k].append(v)
            starts = torch.as_tensor(np.repeat(term | trunc, N), dtype=torch.float32)
        last, _ = learner.critic(torch.as_tensor(agent_centric_state(obs_np).reshape(1, S, -1)), h_c, starts[None])
    data = {k: torch.stack(v) for k, v in out.items()}
    values = learner.value_norm.denormalize(data["values"])
    following = torch.cat([values[1:], learner.value_norm.denormalize(last)])
    next_v = torch.where(data["truncated"], data["next_values"], following)
    data["advantages"], data["returns"] = gae(data["rewards"], values, next_v, data["terminated"],
                                              data["truncated"], cfg.train.gamma, cfg.train.gae_lambda)
    carry.update(obs=obs_np, h_actor=h_a, h_critic=h_c, starts=starts)
    return data


def setup(overrides, seed=3):
    cfg = compose(SMALL + overrides)
    env = VecEnv(cfg, num_envs=cfg.train.num_envs, seed=seed)
    obs = env.reset()
    learner = Learner(cfg, obs.shape[-1], env.n)
    with torch.no_grad():  # a trained-looking value scale, so that denormalising matters
        learner.value_norm.update(torch.randn(500) * 3 + 1)
    return cfg, env, learner, initial_carry(obs, cfg.train.hidden)


@pytest.mark.parametrize("overrides", [["env.n_agents=2"], ["env=homing", "arena.layout=none"]],
                         ids=["two foragers", "homing"])
def test_the_critics_single_pass_gives_the_stepped_rollout(overrides):
    cfg, env, learner, carry = setup(overrides)
    cfg_ref, env_ref, learner_ref, carry_ref = setup(overrides)
    for update in range(2):  # the second rollout starts from the carry the first handed on
        ro, episode = collect(cfg, env, learner, carry, torch.Generator().manual_seed(update))
        ref = stepped_rollout(cfg_ref, env_ref, learner_ref, carry_ref, torch.Generator().manual_seed(update))
        assert ref["truncated"].any() and not ref["truncated"].all()
        for key in ("values", "logp", "advantages", "returns", "h_critic"):
            assert torch.allclose(getattr(ro, key), ref[key], rtol=1e-5, atol=1e-5), key
        assert torch.allclose(carry["h_critic"], carry_ref["h_critic"], rtol=1e-5, atol=1e-5)
        assert torch.equal(carry["h_actor"], carry_ref["h_actor"]) and np.array_equal(carry["obs"], carry_ref["obs"])
        assert np.isfinite(episode["episode_return"]) and episode["episodes_ended"] > 0

