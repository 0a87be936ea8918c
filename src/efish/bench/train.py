"""``efish bench train``: rollout, update and end-to-end speed, and model-FLOP utilisation.

MFU = achieved model FLOP/s of the PPO update / peak GEMM FLOP/s measured in the
same run at the same dtype (fp32 and bf16). Model FLOPs are counted
analytically: 2 per multiply-add of every Linear and GRU matrix, backward = 2 x
forward. Each width also reports the GEMM of its training shapes in both
precisions, the measurement ``train.precision=auto`` decides by (timed anew
here; training keeps each machine's first: efish.rl.compute.machine_rates),
and which precision auto would take by it.

The GEMMs are timed first: they are cheap, and a precision whose training-shape
GEMM runs below ``bench.train_skip_below`` of the fastest one's is not timed
further (its row says so). Without AVX-512, bf16 products run ~50x below fp32
(0.9 against 47 GFLOP/s on an AMD EPYC with torch's AVX2 kernels), and timing a
paper-size bf16 update there took over 25 minutes to confirm what auto had
already decided. Every row carries the CPU's model and torch capability.
"""

from __future__ import annotations

import dataclasses
import time
from typing import Callable

import torch

from ..config.schema import EfishConfig
from ..env.observe import observation_size
from ..rl.compute import DTYPES, Compute, choose_precision, resolve_device, synchronizer
from ..rl.compute import pass_sequences as timed_sequences  # the pass shape the update runs, hence times
from ..rl.mappo import Rollout, ppo_update
from ..rl.networks import Actor, Critic
from ..rl.value_norm import ValueNormalizer
from .timing import best_time, gpu, machine, machine_line

CPU = torch.device("cpu")


def gemm_flops(dtype: torch.dtype, device: torch.device = CPU,
               sizes: tuple[int, ...] = (512, 1024, 2048), repeats: int = 10, size_seconds: float = 1.0,
               max_call_seconds: float = 1.0) -> float:
    """Peak FLOP/s of square matrix products at ``dtype`` on ``device``: the best over sizes and up to ``repeats``
    calls each (each call waited for, so a GPU's asynchronous launch is not timed as the product).

    Bounded in time whatever the speed: a size's repeats stop after about ``size_seconds``, and a larger size is
    not tried when the last one's time predicts (n cubed) a product longer than ``max_call_seconds``. So a slow
    precision (bf16 at ~1 GFLOP/s without AVX-512) costs a second or two, not minutes."""
    best = 0.0
    sync = synchronizer(device)
    for i, n in enumerate(sizes):
        a, b = torch.randn(n, n).to(device, dtype), torch.randn(n, n).to(device, dtype)
        t0 = time.perf_counter()
        a @ b  # the warm-up call, which also says what one call costs
        sync()
        first = time.perf_counter() - t0
        calls = max(1, min(repeats, int(size_seconds / max(first, 1e-9))))
        seconds = min(first, best_time(lambda a=a, b=b: (a @ b, sync()), calls, warmup=False))
        best = max(best, 2 * n ** 3 / seconds)
        if i + 1 < len(sizes) and seconds * (sizes[i + 1] / n) ** 3 > max_call_seconds:
            break
    return best


def skipped_precisions(rates: dict[str, float], below: float, keep: str | None = None) -> dict[str, str]:
    """The precisions not worth timing further, each with the note of its row: those whose GEMM rate (``rates``,
    FLOP/s per precision at the training shape) is below ``below`` times the fastest's. ``keep`` (the precision
    ``train.precision=auto`` takes, the one training would run) is always timed."""
    fastest = max(rates, key=rates.__getitem__)
    return {p: f"skipped: {p} GEMM {r / 1e9:.3g} GFLOP/s vs {fastest} {rates[fastest] / 1e9:.3g}"
            for p, r in rates.items() if r < below * rates[fastest] and p != keep}


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
    from ..rl.collect import collect, initial_carry
    from ..rl.train import Learner

    t = dataclasses.replace(cfg.train, rollout_steps=steps, chunk=steps)
    run = dataclasses.replace(cfg, train=t)
    env = VecEnv(run, num_envs=t.num_envs, seed=0)
    obs = env.reset()
    learner = Learner(run, obs.shape[-1], env.n, device)
    carry = initial_carry(obs, t.hidden, device)
    t0 = time.perf_counter()
    collect(run, env, learner, carry, torch.Generator().manual_seed(0))
    return steps * t.num_envs / (time.perf_counter() - t0)


def _with_hidden(cfg: EfishConfig, hidden: int) -> EfishConfig:
    return dataclasses.replace(cfg, train=dataclasses.replace(cfg.train, hidden=hidden))


def bench_train(cfg: EfishConfig, hiddens: tuple[int, ...] | None = None, rollout_steps: int = 50,
                progress: Callable[[str], object] | None = None) -> list[dict]:
    """One row per (hidden width, precision fp32 and bf16): the peak and training-shape GEMM rates, whether
    ``train.precision=auto`` takes this precision, the update timed at the configured pass shape
    (:func:`timed_sequences` x ``train.chunk``), a short rollout, and the end-to-end rate they imply.

    ``hiddens`` defaults to ``bench.train_hidden``. Every GEMM is timed first; a precision
    :func:`skipped_precisions` names (``bench.train_skip_below``) keeps its GEMM rates, None for the update's
    and end-to-end rates, and the reason in ``note``. ``progress`` receives a line as each step starts or ends,
    so a long run is not silent; every row has the CPU's ``cpu`` and ``cpu_capability``, and on a GPU
    (``train.device=cuda``, ``--device``) its ``gpu``, where the GEMMs, the update and the rollout's networks run."""
    hiddens = tuple(cfg.bench.train_hidden if hiddens is None else hiddens)
    if not hiddens or min(hiddens) < 1:
        raise ValueError(f"bench train needs at least one width, each >= 1; got {list(hiddens)}")
    say = progress or (lambda line: None)
    torch.set_num_threads(cfg.train.threads)
    device = resolve_device(cfg.train.device)
    info = {**machine(), **gpu(device)}
    say(f"{machine_line(info)}; {cfg.train.threads} torch thread(s), update on {device}")
    obs_dim, n_agents = observation_size(cfg), cfg.env.n_agents
    peaks = {}
    for precision, dtype in DTYPES.items():
        peaks[precision] = gemm_flops(dtype, device)
        say(f"peak GEMM {precision}: {peaks[precision] / 1e9:.3g} GFLOP/s")
    autos = {}  # every width's training-shape GEMMs before any update: cheap, and they decide what is timed
    for hidden in hiddens:
        c = _with_hidden(cfg, hidden)
        autos[hidden] = auto = choose_precision(c.train, (timed_sequences(c), hidden, 3 * hidden), device)
        rates = ", ".join(f"{p} {r / 1e9:.3g}" for p, r in auto.gemm_flops.items())
        say(f"width {hidden}: training GEMM {rates} GFLOP/s; train.precision=auto takes {auto.precision}")
    say("compiling the env's kernels (a 2-step rollout, not timed)")
    rollout_rate(_with_hidden(cfg, min(hiddens)), 2, device)  # else the first width's rollout would time the JIT
    rows = []
    for hidden in hiddens:
        c, auto = _with_hidden(cfg, hidden), autos[hidden]
        skip = skipped_precisions(auto.gemm_flops, cfg.bench.train_skip_below, keep=auto.precision)
        say(f"width {hidden}: timing a {rollout_steps}-step rollout")
        env_s = rollout_rate(c, rollout_steps, device)  # the rollout runs in fp32 whatever the update's precision
        per_update = c.train.rollout_steps * c.train.num_envs
        for precision, peak in peaks.items():
            row = {"hidden": hidden, "precision": precision, "gemm_gflops": peak / 1e9,
                   "train_gemm_gflops": auto.gemm_flops[precision] / 1e9, "auto": auto.precision == precision,
                   "update_samples_per_s": None, "update_gflops": None, "mfu": None,
                   "rollout_env_steps_per_s": env_s, "end_to_end_env_steps_per_s": None,
                   "note": skip.get(precision, ""), **info}
            if precision in skip:
                say(f"width {hidden} {precision}: {skip[precision]}")
            else:
                say(f"width {hidden} {precision}: timing the update ({timed_sequences(c)} sequences x "
                    f"{c.train.chunk} steps)")
                samples_s, flops_s = update_rate(c, obs_dim, n_agents, timed_sequences(c), c.train.chunk,
                                                 Compute(device, precision))
                update_s = per_update * n_agents * c.train.epochs / samples_s
                row.update(update_samples_per_s=samples_s, update_gflops=flops_s / 1e9, mfu=flops_s / peak,
                           end_to_end_env_steps_per_s=per_update / (per_update / env_s + update_s))
                say(f"width {hidden} {precision}: {samples_s:,.0f} update samples/s")
            rows.append(row)
    return rows


def _cell(value: float | None, spec: str, width: int) -> str:
    return f"{'-':>{width}}" if value is None else f"{value:>{width}{spec}}"


def format_train(rows: list[dict]) -> str:
    """The rows as an aligned table under the machine's line; ``*`` marks the precision ``train.precision=auto``
    would take, a skipped precision shows ``-`` and its note."""
    head = f"{'hidden':>6} {'prec':>6} {'GEMM GF/s':>10} {'train GEMM GF/s':>16} {'update samples/s':>17} " \
           f"{'update GF/s':>12} {'MFU':>6} {'rollout env-steps/s':>20} {'end-to-end env-steps/s':>23}  note"
    lines = [machine_line(rows[0]) if rows else machine_line({}), head]
    lines += [f"{r['hidden']:>6} {r['precision'] + ('*' if r['auto'] else ''):>6} {r['gemm_gflops']:>10.1f} "
              f"{r['train_gemm_gflops']:>16.1f} {_cell(r['update_samples_per_s'], ',.0f', 17)} "
              f"{_cell(r['update_gflops'], '.1f', 12)} {_cell(r['mfu'], '.1%', 6)} "
              f"{r['rollout_env_steps_per_s']:>20,.0f} {_cell(r['end_to_end_env_steps_per_s'], ',.1f', 23)}"
              f"  {r.get('note', '')}".rstrip() for r in rows]
    note = ("GEMM: peak of square products; train GEMM: one pass's sequences x width times width x 3 width; "
            "* the precision train.precision=auto takes; - not timed (bench.train_skip_below)")
    return "\n".join([*lines, note])
