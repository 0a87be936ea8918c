"""``efish bench group``: what grouped rollouts save, K policies on the same episodes in one env against one by one.

A step of an assay costs mostly the same whatever its number of arenas (the
environment's and the recording's work per step, one network call per policy),
so K policies run as the members of one env (:func:`efish.rollout.group.run_group`)
should cost less than K runs alone. This times both on the first condition of
``bench.group_assay`` with untrained policies of the scale's width, one thread,
the two timed in turn (best of ``bench.repeats`` rounds each), so that both see the
same machine speed. A job that runs alone also pays its start-up (imports, the
config, numba's cache), which this does not count.
"""

from __future__ import annotations

import dataclasses

import torch

from ..config.schema import EfishConfig
from ..env.observe import observation_size
from ..rl.networks import Actor
from ..rl.policy import Policy
from ..rollout.assay import condition_configs
from ..rollout.group import run_group
from ..rollout.run import run_episodes
from .timing import best_times_interleaved, machine, machine_line


def untrained_policies(cfg: EfishConfig, count: int) -> list[Policy]:
    """``count`` untrained actors of the scale's width, each from its own torch seed (so they act differently)."""
    policies = []
    for seed in range(count):
        torch.manual_seed(seed)
        policies.append(Policy(Actor(observation_size(cfg), cfg.train.hidden), cfg.env.n_agents))
    return policies


def bench_group(cfg: EfishConfig, overrides: list[str] = (), sizes: list[int] | None = None,
                episodes: int | None = None, steps: int | None = None) -> list[dict]:
    """One row per group size K (``bench.group_sizes``): seconds of K runs alone and of one grouped run, their
    ratio, and the env-steps (arena steps) per second of each, with the CPU's ``cpu`` and ``cpu_capability``.
    ``overrides`` are the command's (they apply to the assay's condition as to the run's config)."""
    b = cfg.bench
    sizes = list(b.group_sizes if sizes is None else sizes)
    episodes = b.group_episodes if episodes is None else episodes
    steps = b.group_steps if steps is None else steps
    if not sizes or min(sizes) < 1 or episodes < 1 or steps < 1:
        raise ValueError(f"bench group needs group sizes >= 1, episodes >= 1 and steps >= 1; got sizes {sizes}, "
                         f"{episodes} episodes, {steps} steps")
    torch.set_num_threads(1)
    name, run_cfg = next(iter(condition_configs([f"assay={b.group_assay}", *overrides]).items()))
    run_cfg = dataclasses.replace(run_cfg, env=dataclasses.replace(run_cfg.env, episode_steps=steps),
                                  train=cfg.train)
    seed, info, rows = run_cfg.assay.seed, machine(), []
    for k in sizes:
        policies = untrained_policies(run_cfg, k)

        def alone(policies=policies):
            for policy in policies:
                run_episodes(run_cfg, policy, episodes, seed=seed)

        def grouped(policies=policies):
            run_group(run_cfg, policies, episodes, seed=seed)

        alone_s, grouped_s = best_times_interleaved([alone, grouped], b.repeats)
        env_steps = k * episodes * steps
        rows.append({"assay": b.group_assay, "condition": name, "policies": k, "episodes": episodes, "steps": steps,
                     "hidden": run_cfg.train.hidden, "alone_s": alone_s, "grouped_s": grouped_s,
                     "speedup": alone_s / grouped_s, "alone_env_steps_per_s": env_steps / alone_s,
                     "grouped_env_steps_per_s": env_steps / grouped_s, **info})
    return rows


def format_group(rows: list[dict]) -> str:
    """The rows as an aligned table under the machine's line."""
    head = f"{'policies':>8} {'episodes':>8} {'steps':>6} {'alone s':>8} {'grouped s':>10} {'speed-up':>8} " \
           f"{'alone env-steps/s':>18} {'grouped env-steps/s':>20}"
    lines = [machine_line(rows[0]) if rows else machine_line({}),
             f"{rows[0]['assay']} ({rows[0]['condition']}), width {rows[0]['hidden']}, one thread" if rows else "",
             head]
    lines += [f"{r['policies']:>8} {r['episodes']:>8} {r['steps']:>6} {r['alone_s']:>8.2f} {r['grouped_s']:>10.2f} "
              f"{r['speedup']:>7.2f}x {r['alone_env_steps_per_s']:>18,.0f} {r['grouped_env_steps_per_s']:>20,.0f}"
              for r in rows]
    return "\n".join(lines)
