"""``efish watch <run>``: every training job of a run in one table, refreshed while they train
(docs/methods/training.md#live-logs).

A job is a folder under ``results/<run>/train/``: a foraging seed (``seed_N``) or a policy recipe
(``homing``). Its state comes from its files: finished once final.pt is there, running while it has
metrics.parquet and no final.pt (a killed job looks running too: its last update's age says it is not), not
started before its first update. Training rewrites metrics.parquet atomically after every update, so reading it
while a job runs is safe. When the run is a shipped scale (``results/smoke``, no overrides), the scale's config
also gives the seeds that have not started yet and each job's updates where its metrics do not record them;
for any other run those come from the job folders and their metrics alone.
"""

from __future__ import annotations

import math
import sys
import time
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

import pandas as pd

from .config import compose, config_dir
from .io import atomic_path, read_parquet
from .layout import FINAL_POLICY, TRAINING_METRICS, Run, seed_name, training_folder

NOT_STARTED, RUNNING, FINISHED = "not started", "running", "finished"
RATE_ROWS = 10  # the ETA's speed: the mean env steps per second over this many last updates
FORAGING_RECIPE = "foraging"  # config/policy/: what the seeds train on (the policy recipes have folders of their own)
#: The curves of ``--plot``: metrics column -> axis label.
CURVES = {"episode_return": "mean episode return", "entropy": "policy entropy", "approx_kl": "approximate KL"}


@dataclass(frozen=True)
class Job:
    """One training job of a run: its folder name (``seed_3``, ``homing``), its folder, and the updates the run's
    scale gives it (None where the run is no shipped scale)."""

    name: str
    folder: Path
    planned_updates: int | None = None


def training_jobs(run: Run) -> list[Job]:
    """The run's training jobs: those the scale plans (shipped scales) and every folder under ``train/``, seeds
    in seed order, then the policy recipes; one clear error when the run's folder is missing or holds none."""
    if not run.results.is_dir():
        raise ValueError(f"no run folder {run.results}: name a run under --results (efish watch smoke)")
    planned = planned_updates(run.name)
    folders = {p.name: p for p in run.results.glob(training_folder("*")) if p.is_dir()}
    names = sorted(set(planned) | set(folders), key=_job_order)
    if not names:
        raise ValueError(f"{run.path(training_folder(''))} holds no training jobs (seed_N or policy folders) yet")
    updates = {name: planned[name] if name in planned else _recipe_updates(run.name, name) for name in names}
    return [Job(name, run.path(training_folder(name)), updates[name]) for name in names]


def planned_updates(run_name: str) -> dict[str, int]:
    """Seed folder -> updates, of every seed a shipped scale trains; {} for another run (its overrides, which may
    change both, are not recorded in its name)."""
    if not _is_shipped_scale(run_name):
        return {}
    cfg = compose([f"scale={run_name}", f"policy={FORAGING_RECIPE}"])
    return {seed_name(seed): cfg.train.total_updates() for seed in cfg.scale.seed_numbers()}


def _recipe_updates(run_name: str, name: str) -> int | None:
    """The updates of a policy recipe's job under a shipped scale, else None."""
    if not _is_shipped_scale(run_name) or not (config_dir() / "policy" / f"{name}.yaml").is_file():
        return None
    return compose([f"scale={run_name}", f"policy={name}"]).train.total_updates()


def _is_shipped_scale(run_name: str) -> bool:
    return (config_dir() / "scale" / f"{run_name}.yaml").is_file()


def _job_order(name: str) -> tuple:
    """Seeds first, by number; then the other folders by name."""
    number = name.removeprefix(seed_name(""))
    return (0, int(number), "") if name.startswith(seed_name("")) and number.isdigit() else (1, 0, name)


def read_metrics(job: Job) -> pd.DataFrame | None:
    """The job's metrics so far, with the time they were written in ``.attrs["written"]``; None before its first
    update (or while a workflow has removed them to rerun the job)."""
    path = job.folder / TRAINING_METRICS
    try:
        written = path.stat().st_mtime
        metrics = read_parquet(path, "a training's metrics")  # one open handle: never a torn table
    except FileNotFoundError:
        return None
    metrics.attrs["written"] = written
    return metrics


def job_row(job: Job, metrics: pd.DataFrame | None, now: float) -> dict:
    """One line of the table: where the job is and how it learns (its last update), with its speed and ETA."""
    finished = (job.folder / FINAL_POLICY).exists()
    if metrics is None or metrics.empty:
        total = job.planned_updates
        return {"job": job.name, "state": NOT_STARTED, "update": f"0/{_or_unknown(total)}", "env steps": "0",
                "return": "-", "entropy": "-", "KL": "-", "env-steps/s": "-", "ETA": "-", "last update": "-"}
    last = metrics.iloc[-1]
    update = int(last["update"])
    total = _total_updates(metrics, job, finished)
    returns = metrics["episode_return"].dropna()  # NaN where no episode ended in an update
    rate = metrics["env_steps_per_s"].tail(RATE_ROWS).mean()
    age = max(0.0, now - metrics.attrs.get("written", now))  # a clock a little behind the file server's
    return {"job": job.name, "state": FINISHED if finished else RUNNING, "update": f"{update}/{_or_unknown(total)}",
            "env steps": f"{int(last['env_steps']):,}",
            "return": f"{returns.iloc[-1]:.3f}" if len(returns) else "-",
            "entropy": f"{last['entropy']:.3f}", "KL": f"{last['approx_kl']:.2g}",
            "env-steps/s": f"{last['env_steps_per_s']:,.0f}",
            "ETA": _eta(finished, total, update, int(last["env_steps"]) / update, rate),
            "last update": f"{duration(age)} ago"}


def _total_updates(metrics: pd.DataFrame, job: Job, finished: bool) -> int | None:
    """The job's updates: what its metrics record (the newest row: a resumed, longer run records its new
    total), else the scale's plan, else the last update of a finished job."""
    if "total_updates" in metrics.columns:
        return int(metrics["total_updates"].iloc[-1])
    if job.planned_updates is not None:
        return job.planned_updates
    return int(metrics["update"].iloc[-1]) if finished else None


def _eta(finished: bool, total: int | None, update: int, steps_per_update: float, rate: float) -> str:
    """Time left at the recent speed (the updates' own time: checkpoints and logs add a little)."""
    if finished:
        return "-"
    if total is None or not rate > 0:
        return "?"
    return duration(max(0, total - update) * steps_per_update / rate)


def _or_unknown(total: int | None) -> str:
    return "?" if total is None else str(total)


def duration(seconds: float) -> str:
    """``42s``, ``3m05s``, ``2h07m``: a time span read at a glance."""
    if not math.isfinite(seconds):
        return "?"
    s = int(round(seconds))
    if s < 60:
        return f"{s}s"
    if s < 3600:
        return f"{s // 60}m{s % 60:02d}s"
    return f"{s // 3600}h{s % 3600 // 60:02d}m"


def table(run: Run, jobs: list[Job], metrics: dict[str, pd.DataFrame | None], now: float) -> str:
    """The run's table with a title line: how many jobs are finished, and when it was read."""
    rows = pd.DataFrame([job_row(job, metrics[job.name], now) for job in jobs])
    done = int((rows["state"] == FINISHED).sum())
    title = f"{run.name}: {done}/{len(jobs)} training jobs finished ({time.strftime('%H:%M:%S')})"
    return f"{title}\n{rows.to_string(index=False)}"


def plot_curves(metrics: dict[str, pd.DataFrame | None], path: Path) -> None:
    """Return, entropy and KL against env steps, one line per job that has metrics, as a PNG (atomically, so an
    image viewer open on it never reads half a file)."""
    from .figures.style import panel_style

    with panel_style() as plt:
        fig, axes = plt.subplots(1, len(CURVES), figsize=(11, 3.2), constrained_layout=True)
        for ax, (column, label) in zip(axes, CURVES.items(), strict=True):
            for name, df in metrics.items():
                if df is not None and column in df.columns:
                    points = df[["env_steps", column]].dropna()
                    ax.plot(points["env_steps"], points[column], marker=".", markersize=3, lw=1, label=name)
            ax.set(xlabel="env steps", ylabel=label)
        if any(ax.lines for ax in axes):
            axes[0].legend(fontsize=6)
        with atomic_path(path) as tmp:
            fig.savefig(tmp, format="png", dpi=120)
        plt.close(fig)


def watch(run: Run, interval: float = 10.0, once: bool = False, plot: Path | None = None,
          show: Callable[[str], None] = print) -> None:
    """Show the run's table (and write ``plot``) every ``interval`` seconds until every job is finished, or once.

    On a terminal each table replaces the last; elsewhere (a log file) they follow each other. New job folders
    are picked up as their jobs start.
    """
    if not interval > 0:
        raise ValueError(f"--interval {interval:g} must be above 0 seconds")
    clear = "\x1b[H\x1b[2J" if sys.stdout.isatty() and not once else ""
    while True:
        jobs = training_jobs(run)
        metrics = {job.name: read_metrics(job) for job in jobs}
        if plot is not None:
            plot_curves(metrics, plot)
        show(clear + table(run, jobs, metrics, time.time()))
        if once or all((job.folder / FINAL_POLICY).exists() for job in jobs):
            return
        time.sleep(interval)
