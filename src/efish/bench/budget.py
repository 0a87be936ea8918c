"""``efish bench budget``: what a fixed training time buys, a wider network, more env steps or more seeds.

Every width of ``bench.budget_hidden`` (``--hidden``) trains ``bench.budget_seeds``
(``--seeds``) seeds (1, 2, ...) for the same wall time (``bench.budget_minutes``),
``bench.budget_jobs`` (``--jobs``) runs at a time with one torch thread each, as the
workflow's training jobs run. Each run's metrics (``wall_s``, ``env_steps``,
``episode_return`` per update) are kept, so one set of runs answers three
questions at equal cost, the cost of one seed trained for the whole budget:

- **more env steps**: one seed of the narrowest width for the whole budget
  (the mean over the seeds estimates what one seed reaches);
- **more seeds**: ``seeds`` seeds of that width, each for budget / seeds, the
  best of them (seed selection keeps the best);
- **wider**: one seed of each wider width for the whole budget.

The return at a time t is the mean episode return of the last ``window``
updates that ended by t (updates in which no episode ended are skipped), the
same smoothing scale as the training curves. Training runs in a temporary
folder that is removed afterwards; only the table is kept. One update trained
before the runs compiles the numba kernels, so no run pays for compilation.
"""

from __future__ import annotations

import dataclasses
import math
import tempfile
from concurrent.futures import ProcessPoolExecutor
from multiprocessing import get_context
from pathlib import Path

import numpy as np
import pandas as pd

from ..config.schema import EfishConfig
from .timing import cpu_name

WINDOW = 5  # updates averaged into one return value


class _BudgetSpent(Exception):
    """Raised by the progress callback to end a run when its wall time is spent."""


def train_for(cfg: EfishConfig, hidden: int, seed: int, seconds: float) -> pd.DataFrame:
    """Train ``seed`` at width ``hidden`` for ``seconds`` of wall time; its per-update metrics with hidden and seed."""
    from ..rl.train import train

    t_cfg = dataclasses.replace(cfg.train, hidden=hidden, seed=seed, threads=1, total_steps=10 ** 12)
    run_cfg = dataclasses.replace(cfg, train=t_cfg)
    rows: list[dict] = []

    def stop_when_spent(row: dict, total: int) -> None:
        rows.append(row)
        if row["wall_s"] >= seconds:
            raise _BudgetSpent

    with tempfile.TemporaryDirectory(prefix="efish-budget-") as folder:
        try:
            train(run_cfg, Path(folder), progress=stop_when_spent)
        except _BudgetSpent:
            pass
    return pd.DataFrame(rows).assign(hidden=hidden, seed=seed)


def return_at(run: pd.DataFrame, seconds: float, window: int = WINDOW) -> float:
    """Mean episode return of the last ``window`` updates with an ended episode by ``seconds`` (NaN if none)."""
    done = run[(run["wall_s"] <= seconds) & run["episode_return"].notna()]
    return float(done["episode_return"].tail(window).mean()) if len(done) else math.nan


def steps_at(run: pd.DataFrame, seconds: float) -> int:
    """Env steps trained by ``seconds``."""
    done = run[run["wall_s"] <= seconds]
    return int(done["env_steps"].iloc[-1]) if len(done) else 0


def check_budget(hiddens: tuple[int, ...], seeds: int, minutes: float, jobs: int) -> None:
    """One ValueError line unless minutes > 0, seeds >= 1, jobs >= 1 and every width >= 1."""
    if minutes <= 0 or seeds < 1 or jobs < 1 or not hiddens or min(hiddens) < 1:
        raise ValueError(f"bench budget needs minutes > 0, seeds >= 1, jobs >= 1 and widths >= 1; got "
                         f"minutes={minutes}, seeds={seeds}, jobs={jobs}, widths={list(hiddens)}")


def budget_sizes(cfg: EfishConfig) -> tuple[tuple[int, ...], int, float, int]:
    """(widths, seeds, minutes, jobs) of ``cfg.bench``, checked (:func:`check_budget`)."""
    b = cfg.bench
    sizes = (tuple(b.budget_hidden), b.budget_seeds, b.budget_minutes, b.budget_jobs)
    check_budget(*sizes)
    return sizes


def bench_budget(cfg: EfishConfig, hiddens: tuple[int, ...] | None = None, seeds: int | None = None,
                 minutes: float | None = None, jobs: int | None = None, progress=None) -> pd.DataFrame:
    """Train every (width, seed) for ``minutes``; one row per run and checkpoint time (budget / seeds and budget).
    A size left None is ``cfg.bench``'s (``budget_hidden``, ``budget_seeds``, ``budget_minutes``, ``budget_jobs``).

    Columns: hidden, seed, fraction (of the budget), wall_s, env_steps, episode_return.
    """
    b = cfg.bench
    hiddens = tuple(b.budget_hidden if hiddens is None else hiddens)
    seeds = b.budget_seeds if seeds is None else seeds
    minutes = b.budget_minutes if minutes is None else minutes
    jobs = b.budget_jobs if jobs is None else jobs
    check_budget(hiddens, seeds, minutes, jobs)
    seconds = 60.0 * minutes
    train_for(cfg, min(hiddens), 1, 0.0)  # one update here first compiles the numba kernels for every run
    runs = [(h, s) for h in hiddens for s in range(1, seeds + 1)]
    # spawn: each run is a fresh process with its own single torch thread, like a workflow job
    with ProcessPoolExecutor(max_workers=jobs, mp_context=get_context("spawn")) as pool:
        futures = [pool.submit(train_for, cfg, h, s, seconds) for h, s in runs]
        results = []
        for (h, s), fut in zip(runs, futures, strict=True):
            results.append(fut.result())
            if progress:
                progress(f"width {h} seed {s}")
    fractions = sorted({1.0 / seeds, 1.0})
    rows = [{"hidden": int(run["hidden"].iloc[0]), "seed": int(run["seed"].iloc[0]), "fraction": f,
             "wall_s": f * seconds, "env_steps": steps_at(run, f * seconds), "episode_return": return_at(run, f * seconds)}
            for run in results for f in fractions]
    table = pd.DataFrame(rows)
    table.attrs.update(minutes=minutes, seeds=seeds, jobs=jobs, cpu=cpu_name())
    return table


def options(table: pd.DataFrame) -> pd.DataFrame:
    """The three uses of one seed's budget (see the module docstring), one row each, best first."""
    narrow, seeds = int(table["hidden"].min()), int(table["seed"].max())
    end = table[table["fraction"] == 1.0]
    rows = [{"option": f"more env steps: width {narrow}, one seed for the whole budget",
             "episode_return": end[end["hidden"] == narrow]["episode_return"].mean(),
             "env_steps": end[end["hidden"] == narrow]["env_steps"].mean()}]
    if seeds > 1:
        part = table[(table["hidden"] == narrow) & np.isclose(table["fraction"], 1.0 / seeds)]
        rows.append({"option": f"more seeds: width {narrow}, best of {seeds} seeds for 1/{seeds} of it each",
                     "episode_return": part["episode_return"].max(), "env_steps": part["env_steps"].mean()})
    for h in sorted(set(end["hidden"]) - {narrow}):
        rows.append({"option": f"wider: width {h}, one seed for the whole budget",
                     "episode_return": end[end["hidden"] == h]["episode_return"].mean(),
                     "env_steps": end[end["hidden"] == h]["env_steps"].mean()})
    return pd.DataFrame(rows).sort_values("episode_return", ascending=False, na_position="last").reset_index(drop=True)


def format_budget(table: pd.DataFrame) -> str:
    """The per-run table and the three options, best first."""
    a = table.attrs
    lines = [f"bench budget: {a.get('minutes')} min per run, {a.get('seeds')} seeds per width, "
             f"{a.get('jobs')} runs at a time, one thread each ({a.get('cpu', '?')})",
             f"{'width':>6} {'seed':>5} {'at':>8} {'env steps':>11} {'return':>9}"]
    for r in table.itertuples():
        lines.append(f"{r.hidden:>6} {r.seed:>5} {r.wall_s / 60:>6.3g} m {r.env_steps:>11,} {r.episode_return:>9.3f}")
    lines.append("at the cost of one seed for the whole budget (best first):")
    for r in options(table).itertuples():
        lines.append(f"  {r.episode_return:>9.3f}  {r.option} ({r.env_steps:,.0f} env steps each)")
    return "\n".join(lines)
