"""``efish bench scaling``: how the cost of an agent-step grows with the pellets and the agents of an arena.

Two sweeps, each case a row of ``bench_scaling.parquet`` (see ``COLUMNS``):

- ``pellets``: square arenas of ``bench.scaling_sizes_cm`` at the configured
  food density (so the pellet count grows with the area), with
  ``bench.scaling_n_agents`` agents; plus a crowded case, the first arena with
  ``bench.scaling_crowded_multiplier`` times the food;
- ``agents``: the first arena with each of ``bench.scaling_agents`` agents.

Each case steps ``bench.scaling_envs`` arenas of :class:`~efish.env.VecEnv`
with random actions (the same actions and states for both) at the configured
tolerance ("fast") and at tolerance 0 ("exact"), the two timed in turn
(``bench.reference_rounds`` rounds, best of each) so their ratio shares the
machine's drift. ``max_abs_error`` is the largest difference of normalised
readings between the two on the fast run's final states. Sensing at a cost
that does not grow with the arena shows as a flat ``fast_us_per_agent_step``
against ``pellets``; :func:`plot_scaling` draws it against the constant and
linear references. Example::

    df = bench_scaling(compose(["scale=smoke"]))
    df[["case", "pellets", "fast_agent_steps_per_s", "max_abs_error"]]
"""

from __future__ import annotations

import dataclasses
from pathlib import Path

import numpy as np
import pandas as pd

from ..config.schema import EfishConfig
from ..env.vec_env import VecEnv
from ..sensors.sense import sense_batch
from .env import _random_actions
from .physics import max_reading_difference
from .timing import best_times_interleaved

COLUMNS = ("sweep", "case", "width_cm", "n_agents", "food_multiplier", "pellets", "sources", "envs",
           "fast_agent_steps_per_s", "exact_agent_steps_per_s", "fast_us_per_agent_step", "exact_us_per_agent_step",
           "speedup", "max_abs_error")


@dataclasses.dataclass(frozen=True)
class ScalingCase:
    """One benchmarked scene: a square arena, its food multiplier and agent count."""

    sweep: str              # "pellets" or "agents"
    case: str               # label, e.g. "280x280" or "70x70 crowded x10"
    width_cm: float
    n_agents: int
    food_multiplier: float


def scaling_cases(cfg: EfishConfig) -> list[ScalingCase]:
    """The cases of both sweeps, from ``cfg.bench`` (see the module docstring)."""
    bc = cfg.bench
    if not bc.scaling_sizes_cm:
        raise ValueError("bench.scaling_sizes_cm is empty: the scaling benchmark needs at least one arena size")
    base, mult = float(bc.scaling_sizes_cm[0]), cfg.arena.food_multiplier
    cases = [ScalingCase("pellets", f"{s:g}x{s:g}", float(s), bc.scaling_n_agents, mult) for s in bc.scaling_sizes_cm]
    if bc.scaling_crowded_multiplier > 0:
        cases.append(ScalingCase("pellets", f"{base:g}x{base:g} crowded x{bc.scaling_crowded_multiplier:g}", base,
                                 bc.scaling_n_agents, mult * bc.scaling_crowded_multiplier))
    cases += [ScalingCase("agents", f"{int(n)} agent" + "s" * (int(n) != 1), base, int(n), mult)
              for n in bc.scaling_agents]
    return cases


def case_config(cfg: EfishConfig, case: ScalingCase, tolerance: float | None = None) -> EfishConfig:
    """``cfg`` with the case's arena, food and agents (episodes never end while timed); tolerance if given."""
    arena = dataclasses.replace(cfg.arena, width_cm=case.width_cm, height_cm=case.width_cm,
                                food_multiplier=case.food_multiplier)
    env = dataclasses.replace(cfg.env, n_agents=case.n_agents, obs_agents=max(cfg.env.obs_agents, case.n_agents),
                              episode_steps=10**9, muted=[], frozen=[], bots=[], sizes=[], starts=[])
    physics = cfg.physics if tolerance is None else dataclasses.replace(cfg.physics, tolerance=float(tolerance))
    return dataclasses.replace(cfg, arena=arena, env=env, physics=physics)


def stepper(cfg: EfishConfig, envs: int, agent_steps: int, seed: int):
    """A function stepping ``envs`` arenas with seeded random actions for about ``agent_steps`` agent-steps;
    returns it, the agent-steps of one call and the env (its state is what the last call left)."""
    env = VecEnv(cfg, num_envs=envs, seed=seed)
    env.reset()
    rng = np.random.default_rng(seed)
    acts = [_random_actions(rng, envs, env.n) for _ in range(max(1, -(-agent_steps // (envs * env.n))))]

    def run():
        for a in acts:
            env.step(a)
    return run, envs * env.n * len(acts), env


def bench_case(cfg: EfishConfig, case: ScalingCase) -> dict:
    """Time one case at the configured tolerance and at 0 (in turn) and compare their readings; one row."""
    bc = cfg.bench
    fast_cfg, exact_cfg = case_config(cfg, case), case_config(cfg, case, tolerance=0.0)
    envs, n = bc.scaling_envs, case.n_agents
    fast, fast_n, fast_env = stepper(fast_cfg, envs, bc.scaling_agent_steps, bc.seed)
    exact, exact_n, exact_env = stepper(exact_cfg, envs, bc.scaling_exact_agent_steps, bc.seed)
    fast_s, exact_s = best_times_interleaved([fast, exact], bc.reference_rounds)
    # readings of the final states, with a seeded half of the agents emitting
    eod = np.random.default_rng(bc.seed).random((envs, n)) < 0.5
    batch = fast_env.snapshot(eod)
    error = max_reading_difference(sense_batch(batch, fast_env.plan), sense_batch(batch, exact_env.plan))
    pellets = float(batch.pellet_alive.sum(axis=1).mean())
    fast_rate, exact_rate = fast_n / fast_s, exact_n / exact_s
    return {
        "sweep": case.sweep, "case": case.case, "width_cm": case.width_cm, "n_agents": n,
        "food_multiplier": case.food_multiplier, "pellets": pellets,
        "sources": (pellets + n) * len(fast_env.plan.image_weights), "envs": envs,
        "fast_agent_steps_per_s": fast_rate, "exact_agent_steps_per_s": exact_rate,
        "fast_us_per_agent_step": 1e6 / fast_rate, "exact_us_per_agent_step": 1e6 / exact_rate,
        "speedup": fast_rate / exact_rate, "max_abs_error": error,
    }


def bench_scaling(cfg: EfishConfig, progress=None) -> pd.DataFrame:
    """Every case of :func:`scaling_cases`, one row each (``COLUMNS``); one thread."""
    cases = scaling_cases(cfg)
    rows = [bench_case(cfg, c) for c in (progress(cases) if progress else cases)]
    return pd.DataFrame(rows, columns=list(COLUMNS))


def format_scaling(df: pd.DataFrame) -> str:
    """The table as aligned text, with the throughput of each case relative to the first of its sweep."""
    lines = [f"{'sweep':<8}{'case':<22}{'pellets':>9}{'fast agent-steps/s':>20}{'of first':>10}"
             f"{'exact':>10}{'max error':>11}"]
    for sweep, g in df.groupby("sweep", sort=False):
        first = g["fast_agent_steps_per_s"].iloc[0]
        lines += [f"{sweep:<8}{r.case:<22}{r.pellets:>9,.0f}{r.fast_agent_steps_per_s:>20,.0f}"
                  f"{r.fast_agent_steps_per_s / first:>10.0%}{r.exact_agent_steps_per_s:>10,.0f}{r.max_abs_error:>11.1e}"
                  for r in g.itertuples()]
    return "\n".join(lines)


def plot_scaling(df: pd.DataFrame, path: str | Path) -> None:
    """Cost per agent-step against work, log-log: pellets per arena (left) and agents per arena (right).

    Fast (filled) and exact (open) markers; dotted: a cost that stays constant
    and one that grows linearly with the work, both through the first fast case.
    """
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(1, 2, figsize=(11, 4.5), constrained_layout=True)
    panels = (("pellets", "pellets", "pellets per arena (sweep of arena size; crowded ringed)"),
              ("agents", "n_agents", "agents per arena"))
    for ax, (sweep, xcol, xlabel) in zip(axes, panels, strict=True):
        g = df[df["sweep"] == sweep]
        if g.empty:
            from ..figures.style import missing

            missing(ax, f"no {sweep} cases in this run")
            continue
        g = g.sort_values(xcol)
        x = g[xcol].clip(lower=1.0).to_numpy(float)
        crowded = g["case"].str.contains("crowded").to_numpy()  # off the size sweep: markers, no line
        for col, style, label in (("fast_us_per_agent_step", dict(marker="o", color="C0"), "fast (configured tolerance)"),
                                  ("exact_us_per_agent_step", dict(marker="s", color="C1", mfc="none", ls="--"),
                                   "exact (tolerance 0)")):
            ax.plot(x[~crowded], g[col][~crowded], label=label, **style)
            ax.plot(x[crowded], g[col][crowded], ls="none", **{k: v for k, v in style.items() if k != "ls"})
        ax.scatter(x[crowded], g["fast_us_per_agent_step"][crowded], s=180, facecolors="none", edgecolors="k")
        x0, y0 = x[0], g["fast_us_per_agent_step"].iloc[0]
        span = np.geomspace(x.min(), x.max(), 50)
        ax.plot(span, np.full_like(span, y0), ":", color="grey", label="constant")
        ax.plot(span, y0 * span / x0, ":", color="k", label="linear in the work")
        for xi, (_, r) in zip(x, g.iterrows(), strict=True):
            ax.annotate(r["case"], (xi, r["fast_us_per_agent_step"]), fontsize=6, xytext=(3, -9),
                        textcoords="offset points")
        ax.set(xscale="log", yscale="log", xlabel=xlabel, ylabel="us per agent-step (one thread)")
        ax.legend(fontsize=7)
    fig.suptitle("Sensing cost per agent-step against the work of the scene")
    fig.savefig(path, dpi=150)
    plt.close(fig)
