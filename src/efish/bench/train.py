"""``efish bench train``: rollout, update and end-to-end speed, and model-FLOP utilisation.

MFU = achieved model FLOP/s of the PPO update / peak GEMM FLOP/s measured in the
same run at the same dtype (fp32 and bf16). Model FLOPs are counted
analytically: 2 per multiply-add of every Linear and GRU matrix, backward = 2 x
forward. Each width also reports the GEMM of its training shapes in both
precisions, the measurement ``train.precision=auto`` decides by, and which
precision auto would take.
"""

from __future__ import annotations

import dataclasses
import time

import torch

from ..config.schema import EfishConfig
from ..env.observe import observation_size
from ..rl.compute import Compute, choose_precision, resolve_device
from ..rl.compute import pass_sequences as timed_sequences  # the pass shape the update runs, hence times
from ..rl.mappo import Rollout, ppo_update
from ..rl.networks import Actor, Critic
from ..rl.value_norm import ValueNormalizer
from .timing import best_time


def gemm_flops(dtype: torch.dtype, sizes: tuple[int, ...] = (512, 1024, 2048), repeats: int = 10) -> float:
    """Peak FLOP/s of square matrix products at ``dtype``: the best over sizes and ``repeats``."""
    best = 0.0
    for n in sizes:
        a, b = torch.randn(n, n).to(dtype), torch.randn(n, n).to(dtype)
        best = max(best, 2 * n ** 3 / best_time(lambda a=a, b=b: a @ b, repeats))
    return best


def forward_flops(input_dim: int, hidden: int, out_dim: int) -> int:
    """Multiply-add FLOPs of one trunk + head forward for one sample (LayerNorms neglected)."""
    mlp = 2 * input_dim * hidden + 2 * hidden * hidden
    gru = 2 * 3 * (hidden * hidden + hidden * hidden)
    return mlp + gru + 2 * hidden * out_dim


def update_rate(cfg: EfishConfig, obs_dim: int, n_agents: int, sequences: int, steps: int,
                compute: Compute) -> tuple[float, float]:
    """(samples/s, model FLOP/s) of one PPO epoch over ``sequences`` sequences of ``steps`` steps (one chunk
    each), on a synthetic rollout, in ``compute``'s device and precision. Timing one pass of the configured
    shape (:func:`timed_sequences` x ``train.chunk``) gives the update's throughput without a paper-size epoch."""
    t = dataclasses.replace(cfg.train, epochs=1, minibatches=1, rollout_steps=steps, chunk=steps)
    dev = compute.device
    actor, critic = Actor(obs_dim, t.hidden).to(dev), Critic(obs_dim * n_agents, t.hidden).to(dev)
    opt_a, opt_c = torch.optim.Adam(actor.parameters()), torch.optim.Adam(critic.parameters())
    n_chunks = steps // t.chunk
    ro = Rollout(obs=torch.randn(steps, sequences, obs_dim), state=torch.randn(steps, sequences, obs_dim * n_agents),
                 actions=torch.randn(steps, sequences, 4).clamp(0, 1).round(), logp=torch.zeros(steps, sequences),
                 values=torch.zeros(steps, sequences), advantages=torch.randn(steps, sequences),
                 returns=torch.randn(steps, sequences), starts=torch.zeros(steps, sequences),
                 h_actor=torch.zeros(n_chunks, sequences, t.hidden), h_critic=torch.zeros(n_chunks, sequences, t.hidden))
    ro = Rollout(**{k: v.to(dev) for k, v in vars(ro).items()})
    gen = torch.Generator().manual_seed(0)
    norm = ValueNormalizer().to(dev)
    seconds = best_time(lambda: ppo_update(t, actor, critic, opt_a, opt_c, norm, ro, gen, compute), 2)
    samples = steps * sequences
    flops = 3 * samples * (forward_flops(obs_dim, t.hidden, 4) + forward_flops(obs_dim * n_agents, t.hidden, 1))
    return samples / seconds, flops / seconds


def rollout_rate(cfg: EfishConfig, steps: int, device: torch.device) -> float:
    """Env-steps/s (arena steps x arenas) of collecting a rollout with an untrained policy on ``device``."""
    from ..env.vec_env import VecEnv
    from ..rl.train import Learner, collect, initial_carry

    t = dataclasses.replace(cfg.train, rollout_steps=steps, chunk=steps)
    run = dataclasses.replace(cfg, train=t)
    env = VecEnv(run, num_envs=t.num_envs, seed=0)
    obs = env.reset()
    learner = Learner(run, obs.shape[-1], env.n, device)
    carry = initial_carry(obs, t.hidden, device)
    t0 = time.perf_counter()
    collect(run, env, learner, carry, torch.Generator().manual_seed(0))
    return steps * t.num_envs / (time.perf_counter() - t0)


def bench_train(cfg: EfishConfig, hiddens: tuple[int, ...], rollout_steps: int = 50) -> list[dict]:
    """One row per (hidden width, precision fp32 and bf16): the peak and training-shape GEMM rates, whether
    ``train.precision=auto`` takes this precision, the update timed at the configured pass shape
    (:func:`timed_sequences` x ``train.chunk``), a short rollout, and the end-to-end rate they imply."""
    torch.set_num_threads(cfg.train.threads)
    device = resolve_device(cfg.train.device)
    obs_dim, n_agents = observation_size(cfg), cfg.env.n_agents
    peaks = {"fp32": gemm_flops(torch.float32), "bf16": gemm_flops(torch.bfloat16)}
    rows = []
    for hidden in hiddens:
        c = dataclasses.replace(cfg, train=dataclasses.replace(cfg.train, hidden=hidden))
        auto = choose_precision(c.train, (timed_sequences(c), hidden, 3 * hidden), device)
        env_s = rollout_rate(c, rollout_steps, device)  # the rollout runs in fp32 whatever the update's precision
        for precision, peak in peaks.items():
            samples_s, flops_s = update_rate(c, obs_dim, n_agents, timed_sequences(c), c.train.chunk,
                                             Compute(device, precision))
            per_update = c.train.rollout_steps * c.train.num_envs
            update_s = per_update * n_agents * c.train.epochs / samples_s
            rows.append({"hidden": hidden, "precision": precision, "gemm_gflops": peak / 1e9,
                         "train_gemm_gflops": auto.gemm_flops[precision] / 1e9, "auto": auto.precision == precision,
                         "update_samples_per_s": samples_s, "update_gflops": flops_s / 1e9, "mfu": flops_s / peak,
                         "rollout_env_steps_per_s": env_s,
                         "end_to_end_env_steps_per_s": per_update / (per_update / env_s + update_s)})
    return rows


def format_train(rows: list[dict]) -> str:
    """The rows as an aligned table; ``*`` marks the precision ``train.precision=auto`` would take."""
    head = f"{'hidden':>6} {'prec':>6} {'GEMM GF/s':>10} {'train GEMM GF/s':>16} {'update samples/s':>17} " \
           f"{'update GF/s':>12} {'MFU':>6} {'rollout env-steps/s':>20} {'end-to-end env-steps/s':>23}"
    lines = [head] + [f"{r['hidden']:>6} {r['precision'] + ('*' if r['auto'] else ''):>6} {r['gemm_gflops']:>10.1f} "
                      f"{r['train_gemm_gflops']:>16.1f} {r['update_samples_per_s']:>17,.0f} {r['update_gflops']:>12.1f} "
                      f"{r['mfu']:>6.1%} {r['rollout_env_steps_per_s']:>20,.0f} "
                      f"{r['end_to_end_env_steps_per_s']:>23,.1f}" for r in rows]
    note = ("GEMM: peak of square products; train GEMM: one pass's sequences x width times width x 3 width; "
            "* the precision train.precision=auto takes")
    return "\n".join([*lines, note])
