"""``efish watch <run>``: every training job of a run in one table, refreshed while they train
(docs/methods/training.md#live-logs).

A job is a folder under ``results/<run>/train/``: a foraging seed (``seed_N``) or a policy recipe
(``homing``). Its state comes from its files: finished once final.pt is there, running while it has
metrics.parquet and no final.pt (a killed job looks running too: its last update's age says it is not), not
started before its first update. Training rewrites metrics.parquet atomically after every update, so reading it
while a job runs is safe. When the run is a shipped scale (``results/smoke``, no overrides), its run plan
(:class:`efish.run_plan.RunPlan`) also gives the jobs that have not started yet (the seeds and every policy
recipe its assays act with), so the job count is right from the first call, and each job's updates where its
metrics do not record them; for any other run those come from the job folders and their metrics alone.

The table's return is smoothed (:data:`RETURN_WINDOW`): one update's mean return swings with the few episodes
that ended in it, so the last one alone misranks seeds. The ETA divides the steps left by the job's median
speed over all its updates, which a burst of load on the machine does not move.
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
from .layout import FINAL_POLICY, TRAINING_METRICS, Run, parse_recipe_draw, seed_name, training_folder

NOT_STARTED, RUNNING, FINISHED = "not started", "running", "finished"
#: The table's return: the mean of this many last finite episode returns (updates where no episode ended have none).
RETURN_WINDOW = 10
SMOOTHED = f"return ({RETURN_WINDOW})"  # the table's column of the smoothed return, named with its window
FORAGING_RECIPE = "foraging"  # config/policy/: what the seeds train on (the policy recipes have folders of their own)
#: Metrics columns ``--plot`` does not draw: the x axis and the bookkeeping.
NOT_CURVES = ("update", "total_updates", "env_steps", "wall_s")
#: Axis labels of the curves whose column name does not say enough; every other numeric column is drawn as named.
CURVE_LABELS = {"episode_return": "mean episode return", "entropy": "policy entropy", "approx_kl": "approximate KL",
                "env_steps_per_s": "env steps / s", "episodes_ended": "episodes ended per update"}
#: Panels per row of the plot.
PANELS_PER_ROW = 5


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
    names = sorted(set(planned) | set(folders), key=job_order)
    if not names:
        raise ValueError(f"{run.path(training_folder(''))} holds no training jobs (seed_N or policy folders) yet")
    updates = {name: planned[name] if name in planned else _recipe_updates(run.name, name) for name in names}
    return [Job(name, run.path(training_folder(name)), updates[name]) for name in names]


def planned_updates(run_name: str) -> dict[str, int | None]:
    """Job folder -> updates, of every job a shipped scale trains: its seeds and the policy recipes its assays act
    with (the run plan's training targets); {} for another run (its overrides, which may change both, are not
    recorded in its name)."""
    if not is_shipped_scale(run_name):
        return {}
    from .run_plan import RunPlan  # the plan composes every assay: only for a shipped scale

    cfg = compose([f"scale={run_name}", f"policy={FORAGING_RECIPE}"])
    seeds = {seed_name(seed): cfg.train.total_updates() for seed in cfg.scale.seed_numbers()}
    targets = RunPlan.from_config({"scale": run_name}).training_targets(Run(run_name))
    recipes = [Path(t).parent.name for t in targets if Path(t).parent.name not in seeds]
    return {**seeds, **{name: _recipe_updates(run_name, name) for name in recipes}}


def _recipe_updates(run_name: str, name: str) -> int | None:
    """The updates of a policy recipe's job (or of a later draw of it, ``homing_draw_2``: the same training with
    another seed) under a shipped scale, else None."""
    recipe = parse_recipe_draw(name)[0]
    if not is_shipped_scale(run_name) or not (config_dir() / "policy" / f"{recipe}.yaml").is_file():
        return None
    return compose([f"scale={run_name}", f"policy={recipe}"]).train.total_updates()


def is_shipped_scale(run_name: str) -> bool:
    """Whether a run's folder name is a scale of config/scale/ as shipped (no overrides): its plan is known."""
    return (config_dir() / "scale" / f"{run_name}.yaml").is_file()


def is_seed(name: str) -> bool:
    """Whether a job folder is a foraging seed's (``seed_3``), not a policy recipe's (``homing``)."""
    number = name.removeprefix(seed_name(""))
    return name.startswith(seed_name("")) and number.isdigit()


def job_order(name: str) -> tuple:
    """The sort key of job folders: seeds first, by number (seed_2 before seed_10); then the other folders by
    name."""
    return (0, int(name.removeprefix(seed_name(""))), "") if is_seed(name) else (1, 0, name)


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
                SMOOTHED: "-", "last return": "-", "entropy": "-", "KL": "-", "env-steps/s": "-", "ETA": "-",
                "last update": "-"}
    last = metrics.iloc[-1]
    update = int(last["update"])
    total = _total_updates(metrics, job, finished)
    returns = metrics["episode_return"].dropna()  # NaN where no episode ended in an update
    rate = metrics["env_steps_per_s"].median()  # the job's steady speed: a burst of load does not move it
    age = max(0.0, now - metrics.attrs.get("written", now))  # a clock a little behind the file server's
    return {"job": job.name, "state": FINISHED if finished else RUNNING, "update": f"{update}/{_or_unknown(total)}",
            "env steps": f"{int(last['env_steps']):,}",
            SMOOTHED: f"{window_mean(returns):.3f}" if len(returns) else "-",
            "last return": f"{returns.iloc[-1]:.3f}" if len(returns) else "-",
            "entropy": f"{last['entropy']:.3f}", "KL": f"{last['approx_kl']:.2g}",
            "env-steps/s": f"{last['env_steps_per_s']:,.0f}",
            "ETA": _eta(finished, total, update, int(last["env_steps"]) / update, rate),
            "last update": f"{duration(age)} ago"}


def smoothed(values: pd.Series, window: int = RETURN_WINDOW) -> pd.Series:
    """A curve smoothed as the table's return is: at each finite value, the mean of the last ``window`` finite
    values up to it (fewer at the start). NaN (an update where no episode ended has no return) is left out, not
    counted as 0; the index (update or env steps) is kept.

    >>> smoothed(pd.Series([1.0, float("nan"), 3.0, 5.0]), window=2).tolist()
    [1.0, 2.0, 4.0]
    """
    return values.dropna().rolling(window, min_periods=1).mean()


def window_mean(values: pd.Series, window: int = RETURN_WINDOW) -> float:
    """The mean of the last ``window`` finite values (NaN where there is none): the table's smoothed return, and
    where a smoothed curve ends (:func:`smoothed`).

    >>> window_mean(pd.Series([1.0, 2.0, 3.0, float("nan")]), window=2)
    2.5
    """
    return float(values.dropna().tail(window).mean())


def _total_updates(metrics: pd.DataFrame, job: Job, finished: bool) -> int | None:
    """The job's updates: what its metrics record (the newest row: a resumed, longer run records its new
    total), else the scale's plan, else the last update of a finished job."""
    if "total_updates" in metrics.columns:
        return int(metrics["total_updates"].iloc[-1])
    if job.planned_updates is not None:
        return job.planned_updates
    return int(metrics["update"].iloc[-1]) if finished else None


def _eta(finished: bool, total: int | None, update: int, steps_per_update: float, rate: float) -> str:
    """Time left at the job's median speed (the updates' own time: checkpoints and logs add a little)."""
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


def curve_columns(metrics: dict[str, pd.DataFrame | None]) -> list[str]:
    """The metrics ``--plot`` draws: every numeric column any job has, except :data:`NOT_CURVES`, in the order the
    jobs' tables have them."""
    columns: dict[str, None] = {}
    for df in metrics.values():
        if df is not None:
            columns.update((c, None) for c in df.select_dtypes("number").columns if c not in NOT_CURVES)
    return list(columns)


def task_groups(names: list[str]) -> dict[str, list[str]]:
    """Jobs grouped by task, each group drawn on its own axes: the foraging seeds together, each policy recipe
    (homing: another task, another reward scale) with its later draws (``homing_draw_2``, scale.homing_seeds)."""
    seeds = [n for n in names if is_seed(n)]
    recipes: dict[str, list[str]] = {}
    for name in (n for n in names if n not in seeds):
        recipes.setdefault(parse_recipe_draw(name)[0], []).append(name)
    return {**({"foraging seeds": seeds} if seeds else {}), **recipes}


def steps_label(value: float, _position=None) -> str:
    """An env-step tick label short enough not to overlap (a matplotlib ``FuncFormatter``'s function).

    >>> steps_label(80_000), steps_label(1_200_000), steps_label(400)
    ('80k', '1.2M', '400')
    """
    for scale, suffix in ((1e6, "M"), (1e3, "k")):
        if abs(value) >= scale:
            return f"{value / scale:g}{suffix}"
    return f"{value:g}"


def plot_curves(metrics: dict[str, pd.DataFrame | None], path: Path, title: str = "") -> None:
    """Every metric (:func:`curve_columns`) against env steps, one panel each and one colour per job, each task
    (:func:`task_groups`) on its own rows of axes, under ``title``; a PNG written atomically, so an image viewer
    open on it never reads half a file."""
    from matplotlib.ticker import FuncFormatter

    from .figures.style import panel_style

    columns = curve_columns(metrics) or ["episode_return"]
    groups = task_groups([n for n, df in metrics.items() if df is not None]) or {"no job has metrics yet": []}
    per_row = min(PANELS_PER_ROW, len(columns))
    rows_per_group = math.ceil(len(columns) / per_row)
    with panel_style() as plt:
        fig, axes = plt.subplots(rows_per_group * len(groups), per_row, squeeze=False, constrained_layout=True,
                                 figsize=(2.6 * per_row, 2.2 * rows_per_group * len(groups)))
        colours = {name: f"C{i % 10}" for i, name in enumerate(metrics)}
        for g, (group, names) in enumerate(groups.items()):
            block = axes[g * rows_per_group:(g + 1) * rows_per_group].ravel()
            for ax, column in zip(block, columns, strict=False):
                for name in names:
                    df = metrics[name]
                    if column in df.columns:
                        points = df[["env_steps", column]].dropna()
                        ax.plot(points["env_steps"], points[column], lw=1, color=colours[name], label=name)
                ax.set_title(f"{group}: {CURVE_LABELS.get(column, column)}", fontsize=7)
                ax.set_xlabel("env steps")
                ax.xaxis.set_major_formatter(FuncFormatter(steps_label))
            for ax in block[len(columns):]:
                ax.axis("off")
            if any(ax.lines for ax in block):
                block[0].legend(fontsize=6)
        fig.suptitle(title or "training curves", fontsize=9)
        with atomic_path(path) as tmp:
            fig.savefig(tmp, format="png", dpi=120)
        plt.close(fig)


def watch(run: Run, interval: float = 10.0, once: bool = False, plot: Path | None = None,
          show: Callable[[str], None] = print) -> None:
    """Show the run's table (and write ``plot``) every ``interval`` seconds until every job is finished (and the
    pipeline, where it has a line), or once.

    On a terminal each table replaces the last; elsewhere (a log file) they follow each other. New job folders
    are picked up as their jobs start. Above the table, for a run of a shipped scale in the workflow's
    ``results/`` (the current folder's), the whole pipeline's jobs done and time left (efish.progress).
    """
    from .progress import pipeline_watch

    if not interval > 0:
        raise ValueError(f"--interval {interval:g} must be above 0 seconds")
    clear = "\x1b[H\x1b[2J" if sys.stdout.isatty() and not once else ""
    pipeline = pipeline_watch(run)
    while True:
        jobs = training_jobs(run)
        metrics = {job.name: read_metrics(job) for job in jobs}
        if plot is not None:
            plot_curves(metrics, plot, f"{run.name}: training curves ({time.strftime('%Y-%m-%d %H:%M:%S')})")
        head = f"{pipeline.line()}\n" if pipeline is not None else ""
        show(clear + head + table(run, jobs, metrics, time.time()))
        trained = all((job.folder / FINAL_POLICY).exists() for job in jobs)
        if once or (trained and (pipeline is None or pipeline.finished)):
            return
        time.sleep(interval)
