"""Generalised advantage estimation with truncation bootstrapping (docs/methods/training.md#mappo)."""

from __future__ import annotations

import torch


def gae(rewards: torch.Tensor, values: torch.Tensor, next_values: torch.Tensor, terminated: torch.Tensor,
        truncated: torch.Tensor, gamma: float, lam: float) -> tuple[torch.Tensor, torch.Tensor]:
    """Advantages and returns, [T, ...] each.

    ``values[t]`` is V(s_t); ``next_values[t]`` is V(s_{t+1}) of the same
    episode: for a truncated step the value of the final observation (the
    episode would have gone on), for a terminated step anything (ignored).
    Advantages never flow across an episode end.
    """
    steps = rewards.shape[0]
    adv = torch.zeros_like(rewards)
    last = torch.zeros_like(rewards[0])
    alive = 1.0 - terminated.to(rewards.dtype)
    cont = 1.0 - (terminated | truncated).to(rewards.dtype)
    for t in reversed(range(steps)):
        delta = rewards[t] + gamma * next_values[t] * alive[t] - values[t]
        last = delta + gamma * lam * cont[t] * last
        adv[t] = last
    return adv, adv + values
