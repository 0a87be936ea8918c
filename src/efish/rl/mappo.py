"""One recurrent MAPPO update: the losses and the epochs over BPTT chunks (docs/methods/training.md#mappo)."""

from __future__ import annotations

from dataclasses import dataclass

import torch
import torch.nn.functional as F

from ..config.schema import TrainConfig
from .compute import CPU_FP32, Compute
from .networks import Actor, Critic
from .value_norm import ValueNormalizer


@dataclass
class Rollout:
    """One rollout, time-major: [T, S] with S = arenas x agents sequences.

    obs [T, S, D]; state [T, S, N*D] (the agent's own observation first);
    actions [T, S, 4]; logp, values (normalised), advantages, returns [T, S];
    starts [T, S] (1 on the first step of an episode); h_actor, h_critic
    [T/L, S, H] hidden states at the start of each chunk of length L.
    """

    obs: torch.Tensor
    state: torch.Tensor
    actions: torch.Tensor
    logp: torch.Tensor
    values: torch.Tensor
    advantages: torch.Tensor
    returns: torch.Tensor
    starts: torch.Tensor
    h_actor: torch.Tensor
    h_critic: torch.Tensor


def chunked(x: torch.Tensor, chunk: int) -> torch.Tensor:
    """[T, S, ...] -> [L, (T/L) * S, ...]: every chunk becomes its own sequence."""
    t, s = x.shape[:2]
    return x.reshape(t // chunk, chunk, s, *x.shape[2:]).transpose(0, 1).reshape(chunk, (t // chunk) * s, *x.shape[2:])


def micro_losses(cfg: TrainConfig, actor: Actor, critic: Critic, data: dict, h_a: torch.Tensor, h_c: torch.Tensor,
                 idx: torch.Tensor, share: float, compute: Compute) -> dict[str, float]:
    """Losses of the sequences ``idx``; backpropagates ``share`` x (actor loss) and ``share`` x (critic loss)
    into the gradients, and returns the unweighted statistics. Forward passes run in ``compute``'s precision."""
    with compute.autocast():
        dist, _, _ = actor(data["obs"][:, idx], h_a[idx], data["starts"][:, idx])
    dist = dist.to(torch.float32)
    logp = dist.log_prob(data["actions"][:, idx])
    ratio = torch.exp(logp - data["logp"][:, idx])
    a = data["adv"][:, idx]
    policy_loss = -torch.min(ratio * a, ratio.clamp(1 - cfg.clip, 1 + cfg.clip) * a).mean()
    entropy = dist.entropy().mean()
    (share * (policy_loss - cfg.entropy_coef * entropy)).backward()

    with compute.autocast():
        values, _ = critic(data["state"][:, idx], h_c[idx], data["starts"][:, idx])
    values = values.float()
    old, tgt = data["values"][:, idx], data["targets"][:, idx]
    clipped = old + (values - old).clamp(-cfg.clip, cfg.clip)
    value_loss = torch.max(F.huber_loss(values, tgt, delta=cfg.huber_delta, reduction="none"),
                           F.huber_loss(clipped, tgt, delta=cfg.huber_delta, reduction="none")).mean()
    (share * cfg.value_coef * value_loss).backward()

    with torch.no_grad():
        log_ratio = logp - data["logp"][:, idx]
        return {"policy_loss": policy_loss.item(), "value_loss": value_loss.item(), "entropy": entropy.item(),
                "approx_kl": float(((ratio - 1) - log_ratio).mean()),
                "clip_fraction": float(((ratio - 1).abs() > cfg.clip).float().mean())}


def ppo_update(cfg: TrainConfig, actor: Actor, critic: Critic, actor_opt: torch.optim.Optimizer,
               critic_opt: torch.optim.Optimizer, value_norm: ValueNormalizer, ro: Rollout,
               generator: torch.Generator, compute: Compute = CPU_FP32) -> dict[str, float]:
    """Epochs of clipped-surrogate and clipped-Huber-value updates; returns mean statistics.

    The rollout lives on ``compute.device``; ``generator`` (the minibatch order) stays on the CPU."""
    value_norm.update(ro.returns)
    targets = value_norm.normalize(ro.returns)
    adv = (ro.advantages - ro.advantages.mean()) / (ro.advantages.std() + 1e-8)
    L = cfg.chunk
    data = {k: chunked(v, L) for k, v in dict(obs=ro.obs, state=ro.state, actions=ro.actions, logp=ro.logp,
                                                values=ro.values, adv=adv, targets=targets, starts=ro.starts).items()}
    h_a, h_c = ro.h_actor.reshape(-1, ro.h_actor.shape[-1]), ro.h_critic.reshape(-1, ro.h_critic.shape[-1])
    n_seq = h_a.shape[0]
    stats: dict[str, list[float]] = {k: [] for k in ("policy_loss", "value_loss", "entropy", "approx_kl", "clip_fraction")}
    for _ in range(cfg.epochs):
        order = torch.randperm(n_seq, generator=generator)
        for idx in order.chunk(cfg.minibatches):
            # One optimiser step per minibatch, as in docs/methods/training.md#mappo; the forward/backward passes run
            # over micro-batches of sequences whose gradients add up to the minibatch's (each loss weighted by
            # its share), because cache-sized passes run faster than one pass over the whole minibatch.
            actor_opt.zero_grad()
            critic_opt.zero_grad()
            sums = dict.fromkeys(stats, 0.0)
            for micro in idx.to(compute.device).split(cfg.micro_sequences):
                share = len(micro) / len(idx)
                for k, v in micro_losses(cfg, actor, critic, data, h_a, h_c, micro, share, compute).items():
                    sums[k] += share * v
            torch.nn.utils.clip_grad_norm_(actor.parameters(), cfg.max_grad_norm)
            actor_opt.step()
            torch.nn.utils.clip_grad_norm_(critic.parameters(), cfg.max_grad_norm)
            critic_opt.step()
            for k, v in sums.items():
                stats[k].append(v)
    out = {k: sum(v) / len(v) for k, v in stats.items()}
    var = float(ro.returns.var())
    out["explained_variance"] = 1.0 - float((ro.returns - value_norm.denormalize(ro.values)).var()) / var if var > 0 else 0.0
    return out
