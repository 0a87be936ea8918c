"""One rollout of the current policy for a PPO update (docs/methods/training.md#mappo).

Only the actor has to step with the environment: its actions drive it. What
the update needs beside them (the critic's values, the log-probabilities of
the actions taken, the critic's inputs, the bootstrap values of truncated
episodes) is computed after the rollout over all of its steps at once: the
critic runs one pass over the rollout (a few large matrix products instead of
one small product per step and layer), the same function of the same
parameters and hidden states as stepping it, so the numbers agree up to
rounding (tests/rl/test_collect.py). A rollout step of the laptop scale (8
arenas x 4 agents) spent about as long in the critic's step as in the
physics; stepping only the actor removes that.
"""

from __future__ import annotations

import numpy as np
import torch

from ..config.schema import EfishConfig
from ..env.vec_env import VecEnv
from ..physics.geometry import conspecific_slots
from .advantages import gae
from .distributions import ActionDistribution
from .mappo import Rollout

CPU = torch.device("cpu")


def agent_centric_state(obs: np.ndarray) -> np.ndarray:
    """[B, N, D] -> [B, N, N*D]: each agent's critic input, its own observation first, then the others in id order."""
    n = obs.shape[1]
    order = np.concatenate([np.arange(n)[:, None], conspecific_slots(n)], axis=1)
    return obs[:, order].reshape(obs.shape[0], n, -1)


def initial_carry(obs: np.ndarray, hidden: int, device: torch.device = CPU) -> dict:
    """What a rollout hands to the next: the last observation [B, N, D], both networks' hidden states [B*N, H],
    episode starts and the running episode return [B*N] (all episodes start now). Tensors live on ``device``."""
    s = obs.shape[0] * obs.shape[1]
    return {"obs": obs, "h_actor": torch.zeros(s, hidden, device=device),
            "h_critic": torch.zeros(s, hidden, device=device), "starts": torch.ones(s, device=device),
            "episode_return": np.zeros(s)}


def carry_to(carry: dict, device: torch.device) -> dict:
    """The carry with its tensors on ``device`` (a checkpoint stores them on the CPU)."""
    return {k: v.to(device) if isinstance(v, torch.Tensor) else v for k, v in carry.items()}


def critic_inputs(obs: np.ndarray) -> np.ndarray:
    """Observations [T, B, N, D] -> the critic's inputs [T, B*N, N*D] (:func:`agent_centric_state` of each)."""
    t, b, n, _ = obs.shape
    return agent_centric_state(obs.reshape(t * b, n, -1)).reshape(t, b * n, -1)


def collect(cfg: EfishConfig, env: VecEnv, learner, carry: dict, generator: torch.Generator) -> tuple[Rollout, dict]:
    """Step the env ``rollout_steps`` times with the current policy of ``learner`` (an
    :class:`efish.rl.train.Learner`); returns the rollout (on the learner's device) and episode stats.
    ``generator`` is a CPU generator: actions are sampled with it whatever the device."""
    t_cfg = cfg.train
    T, L, B, N = t_cfg.rollout_steps, t_cfg.chunk, env.num_envs, env.n
    S = B * N
    dev = learner.device
    obs_np, h_a, starts_now = carry["obs"], carry["h_actor"], carry["starts"]
    observed, actions, means, logits, rewards, terminated, truncated, starts = [], [], [], [], [], [], [], []
    finals: list[tuple[int, np.ndarray, np.ndarray]] = []  # (step, final observations, truncated arenas)
    h_actor_chunks, returns_done, parts = [], [], {}
    with torch.no_grad():
        for t in range(T):
            if t % L == 0:
                h_actor_chunks.append(h_a)
            observed.append(obs_np)
            obs = torch.as_tensor(obs_np.reshape(1, S, -1)).to(dev)
            dist, h_a, _ = learner.actor(obs, h_a, starts_now[None])
            action = dist.sample(generator)
            obs_np, reward, term, trunc, info = env.step(action.reshape(B, N, 4).cpu().numpy())
            if trunc.any():  # bootstrapped below from the value of the final observation
                finals.append((t, info["final_obs"], trunc))
            for name, v in info["reward_parts"].items():
                parts.setdefault(name, []).append(v.mean())
            done = np.repeat(term | trunc, N)
            carry["episode_return"] += reward.reshape(S)
            if done.any():
                returns_done += carry["episode_return"][done].tolist()
                carry["episode_return"][done] = 0.0
            actions.append(action[0])
            means.append(dist.mean[0])
            logits.append(dist.logits[0])
            rewards.append(reward.reshape(S))
            terminated.append(term)
            truncated.append(trunc)
            starts.append(starts_now)
            starts_now = torch.as_tensor(done, dtype=torch.float32).to(dev)
        ro = _rollout(learner, carry, np.stack(observed), obs_np, finals, torch.stack(actions), torch.stack(means),
                      torch.stack(logits), np.stack(rewards), np.repeat(np.stack(terminated), N, axis=1),
                      np.repeat(np.stack(truncated), N, axis=1), torch.stack(starts), starts_now,
                      torch.stack(h_actor_chunks), t_cfg)
    carry.update(obs=obs_np, h_actor=h_a, starts=starts_now)
    episode = {"episode_return": float(np.mean(returns_done)) if returns_done else float("nan"),
               "episodes_ended": len(returns_done),
               **{f"reward_{k}": float(np.mean(v)) for k, v in parts.items()}}
    return ro, episode


def _rollout(learner, carry: dict, observed: np.ndarray, last_obs: np.ndarray, finals: list, actions: torch.Tensor,
             means: torch.Tensor, logits: torch.Tensor, rewards: np.ndarray, terminated: np.ndarray,
             truncated: np.ndarray, starts: torch.Tensor, starts_next: torch.Tensor, h_actor: torch.Tensor,
             t_cfg) -> Rollout:
    """The rollout's tensors from what the actor's steps recorded: the critic's values over all steps in one pass
    (its hidden state carried in ``carry`` from the last rollout and handed on to the next), the log-probabilities,
    GAE advantages and returns. ``terminated``/``truncated`` are per sequence [T, S]."""
    dev, T, L = learner.device, t_cfg.rollout_steps, t_cfg.chunk
    critic, norm = learner.critic, learner.value_norm
    obs = torch.as_tensor(observed.reshape(T, observed.shape[1] * observed.shape[2], -1)).to(dev)
    state = torch.as_tensor(critic_inputs(observed)).to(dev)
    values, hidden = critic.values_along(state, carry["h_critic"], starts)
    # the hidden state before each chunk's first step: the carried one, then the state after the step before it
    h_critic = torch.stack([carry["h_critic"], *hidden[L - 1:T - 1:L]])
    last_state = torch.as_tensor(critic_inputs(last_obs[None])).to(dev)
    last_value, _ = critic(last_state, hidden[-1], starts_next[None])
    carry["h_critic"] = hidden[-1]
    values_dn = norm.denormalize(values)
    following = torch.cat([values_dn[1:], norm.denormalize(last_value)])
    next_v = torch.zeros_like(values_dn)
    truncated_t = torch.as_tensor(truncated).to(dev)
    if finals:  # V(final observation) from the hidden state after the step that ended the episode
        n = observed.shape[2]
        steps = torch.tensor([t for t, _, _ in finals], device=dev)
        final_state = torch.as_tensor(critic_inputs(np.stack([f for _, f, _ in finals]))).to(dev)
        boot, _ = critic(final_state.reshape(1, -1, final_state.shape[-1]),
                         hidden[steps].reshape(-1, hidden.shape[-1]), torch.zeros(1, final_state.shape[0] *
                                                                                final_state.shape[1], device=dev))
        rows = torch.as_tensor(np.repeat(np.stack([tr for _, _, tr in finals]), n, axis=1)).to(dev)
        next_v[steps] = torch.where(rows, norm.denormalize(boot.reshape(len(finals), -1)), next_v[steps])
    next_v = torch.where(truncated_t, next_v, following)
    rewards_t = torch.as_tensor(rewards, dtype=torch.float32).to(dev)
    adv, ret = gae(rewards_t, values_dn, next_v, torch.as_tensor(terminated).to(dev), truncated_t, t_cfg.gamma,
                   t_cfg.gae_lambda)
    log_std = learner.actor.log_std.expand_as(means)
    logp = ActionDistribution(means, log_std, logits).log_prob(actions)
    return Rollout(obs=obs, state=state, actions=actions, logp=logp, values=values, advantages=adv, returns=ret,
                   starts=starts, h_actor=h_actor, h_critic=h_critic)
