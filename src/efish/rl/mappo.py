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


def micro_batch(data: dict[str, torch.Tensor], h_a: torch.Tensor, h_c: torch.Tensor, idx: torch.Tensor
                ) -> tuple[dict[str, torch.Tensor], torch.Tensor, torch.Tensor]:
    """The sequences ``idx`` of the chunked rollout ``data`` ([L, sequences, ...]) and of the chunks' initial hidden
    states [sequences, H]. A micro-batch is a set: its losses are means over it, so the sequences are taken in
    increasing order, and one that holds every sequence (one minibatch of one pass: the laptop scale) is the data
    itself, without a copy of the [L, sequences, N*D] critic input per epoch."""
    idx = idx.sort().values
    if len(idx) == h_a.shape[0]:
        return data, h_a, h_c
    return {k: v.index_select(1, idx) for k, v in data.items()}, h_a[idx], h_c[idx]


def micro_losses(cfg: TrainConfig, actor: Actor, critic: Critic, batch: dict, h_a: torch.Tensor, h_c: torch.Tensor,
                 share: float, compute: Compute) -> dict[str, float]:
    """Losses of a :func:`micro_batch` (its obs and state standardized, :meth:`RecurrentTrunk.standardize`);
    backpropagates ``share`` x (actor loss) and ``share`` x (critic loss) into the gradients, and returns the
    unweighted statistics. Forward passes run in ``compute``'s precision."""
    with compute.autocast():
        dist, _, _ = actor(batch["obs"], h_a, batch["starts"], standardized=True)
    dist = dist.to(torch.float32)
    logp = dist.log_prob(batch["actions"])
    ratio = torch.exp(logp - batch["logp"])
    a = batch["adv"]
    policy_loss = -torch.min(ratio * a, ratio.clamp(1 - cfg.clip, 1 + cfg.clip) * a).mean()
    entropy = dist.entropy().mean()
    (share * (policy_loss - cfg.entropy_coef * entropy)).backward()

    with compute.autocast():
        values, _ = critic(batch["state"], h_c, batch["starts"], standardized=True)
    values = values.float()
    old, tgt = batch["values"], batch["targets"]
    clipped = old + (values - old).clamp(-cfg.clip, cfg.clip)
    value_loss = torch.max(F.huber_loss(values, tgt, delta=cfg.huber_delta, reduction="none"),
                           F.huber_loss(clipped, tgt, delta=cfg.huber_delta, reduction="none")).mean()
    (share * cfg.value_coef * value_loss).backward()

    with torch.no_grad():
        log_ratio = logp - batch["logp"]
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
    with torch.no_grad():  # the input LayerNorms' parameter-free part, once for all epochs
        obs, state = actor.trunk.standardize(ro.obs), critic.trunk.standardize(ro.state)
    data = {k: chunked(v, L) for k, v in dict(obs=obs, state=state, actions=ro.actions, logp=ro.logp,
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
                batch, h_a_micro, h_c_micro = micro_batch(data, h_a, h_c, micro)
                for k, v in micro_losses(cfg, actor, critic, batch, h_a_micro, h_c_micro, share, compute).items():
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
