"""``efish bench env``: env-only throughput with random actions, fast physics vs reference."""

from __future__ import annotations

import dataclasses

import numpy as np

from ..config.schema import EfishConfig
from ..env.vec_env import VecEnv
from .timing import best_times_interleaved, machine, machine_line

# arena option -> (row label, agents)
SCENES = {"patchy70": ("4-agent patchy 70x70", 4), "onepatch": ("2-agent one-patch 150x150", 2)}


def scene_config(cfg: EfishConfig, arena: str) -> EfishConfig:
    """``cfg`` with one benchmark scene's arena and agent count, and episodes that never end: the user's physics,
    sensor and env overrides still apply, so ``efish bench env physics.image_order=2`` times what it says."""
    from ..config import compose

    env = dataclasses.replace(cfg.env, n_agents=SCENES[arena][1], episode_steps=10**9)
    return dataclasses.replace(cfg, arena=compose([f"arena={arena}"]).arena, env=env)


def _random_actions(rng: np.random.Generator, b: int, n: int) -> np.ndarray:
    return np.concatenate([rng.normal(size=(b, n, 2)), rng.integers(0, 2, (b, n, 2))], axis=-1)


def env_runner(cfg: EfishConfig, num_envs: int, steps: int, seed: int, reference: bool = False):
    """A function stepping ``num_envs`` arenas ``steps`` times with random actions, and its agent-steps per call."""
    env = VecEnv(cfg, num_envs=num_envs, seed=seed, reference=reference)  # reference: same env, oracle physics
    env.reset()
    rng = np.random.default_rng(seed)
    acts = [_random_actions(rng, num_envs, env.n) for _ in range(steps)]

    def run():
        for a in acts:
            env.step(a)
    return run, num_envs * env.n * steps


def bench_env(cfg: EfishConfig, num_envs: int | None = None, steps: int | None = None,
              reference_steps: int = 3) -> list[dict]:
    """Throughput rows for the benchmark scenes: fast path, reference, ratio (one thread), with the CPU's ``cpu``
    and ``cpu_capability``. ``num_envs`` and ``steps`` default to ``bench.env_envs`` and ``bench.env_steps``.

    Fast and reference runs alternate (``bench.reference_rounds`` rounds, best of
    each), so the ratio is not skewed by the machine's speed drifting between them.
    """
    num_envs = cfg.bench.env_envs if num_envs is None else num_envs
    steps = cfg.bench.env_steps if steps is None else steps
    if num_envs < 1 or steps < 1:
        raise ValueError(f"bench env needs at least one arena and one step; got {num_envs} arenas, {steps} steps")
    info = machine()
    rows = []
    for arena, (label, _) in SCENES.items():
        scene = scene_config(cfg, arena)
        fast, fast_n = env_runner(scene, num_envs, steps, cfg.bench.seed)
        ref, ref_n = env_runner(scene, num_envs, reference_steps, cfg.bench.seed, reference=True)
        fast()  # compiles
        fast_s, ref_s = best_times_interleaved([fast, ref], cfg.bench.reference_rounds, warmup=False)
        rows.append({"scene": label, "num_envs": num_envs, "fast_agent_steps_per_s": fast_n / fast_s,
                     "reference_agent_steps_per_s": ref_n / ref_s, "speedup": (fast_n / fast_s) / (ref_n / ref_s), **info})
    return rows


def format_env(rows: list[dict]) -> str:
    """The rows as an aligned table under the machine's line."""
    lines = [machine_line(rows[0] if rows else {}), f"{'scene':<28}{'fast agent-steps/s':>20}{'reference':>12}{'speed-up':>10}"]
    lines += [f"{r['scene']:<28}{r['fast_agent_steps_per_s']:>20,.0f}{r['reference_agent_steps_per_s']:>12,.0f}"
              f"{r['speedup']:>9,.0f}x" for r in rows]
    return "\n".join(lines)
