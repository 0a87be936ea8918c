"""``efish compare-runs``: the training curves of several runs (or a sweep's points) on shared axes, and each
metric's final value per run with a 95% t interval over its seeds (docs/tutorials/watch-a-run.md#compare-runs).

A run's curves are its foraging seeds' (``results/<run>/train/seed_N/metrics.parquet``, read as ``efish watch``
reads them); the policy recipes' folders (``train/homing``: another task, another reward scale) are left out.
Each seed's curve of a metric is smoothed as watch smooths its return (:func:`efish.watch.smoothed`: at each
update, the mean of the last :data:`~efish.watch.RETURN_WINDOW` = 10 finite values) and drawn against env steps,
which line up runs of other rollout sizes. A seed's final value is where its smoothed curve ends, the mean of its
last 10 finite values (:func:`efish.watch.window_mean`); a run's is the mean over its seeds with a 95% t interval
over them (n seeds, n - 1 degrees of freedom; none with one seed). A run's mean curve is drawn over the env steps
every one of its seeds reached. Everything is read and checked before anything is written.
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pandas as pd

from .io import TABLE_SUFFIXES, write_table_file
from .layout import RESULTS_ROOT, Run, training_folder
from .watch import (
    CURVE_LABELS,
    PANELS_PER_ROW,
    RETURN_WINDOW,
    Job,
    curve_columns,
    is_seed,
    job_order,
    read_metrics,
    smoothed,
    steps_label,
    window_mean,
)

RETURN = "episode_return"  # the first panel and the table's first rows
LEVEL = 0.95  # the interval over seeds
TABLE_NAME = "compare_runs"  # --out given as a folder: compare_runs.parquet in it
COLUMNS = ("run", "metric", "seeds", "final_mean", "ci_low", "ci_high", "env_steps")


@dataclass(frozen=True)
class RunMetrics:
    """One run's foraging seeds: its name as shown (the run's folder name), its results folder, and each trained
    seed's metrics table (seed folder -> table, in seed order)."""

    name: str
    folder: Path
    seeds: dict[str, pd.DataFrame]

    def has(self, metric: str) -> bool:
        return any(metric in df.columns for df in self.seeds.values())

    def curves(self, metric: str) -> dict[str, pd.Series]:
        """Each seed's smoothed curve of ``metric`` against env steps (the seeds that log it)."""
        return {seed: seed_curve(df, metric) for seed, df in self.seeds.items() if metric in df.columns}

    @property
    def env_steps(self) -> int:
        """The env steps its seeds reached (the fewest, where they differ)."""
        return min(int(df["env_steps"].iloc[-1]) for df in self.seeds.values())


def resolve_run(where: str, results_root: Path = RESULTS_ROOT) -> Run:
    """A run from the command line: a run name under ``results_root`` (``smoke``), else a run's folder (one that
    holds ``train/``); one line of error when it is neither."""
    folder = Path(where)
    named = [Run(where, results_root=Path(results_root))] if len(folder.parts) == 1 and folder.name else []
    folder = folder if folder.name else folder.resolve()  # "." or "..": the folder's own name
    candidates = [*named, Run(folder.name, results_root=folder.parent)]
    for run in candidates:
        if run.path(training_folder("")).is_dir():
            return run
    tried = " nor ".join(str(run.path(training_folder(""))) for run in candidates)
    raise ValueError(f"no run {where!r}: neither {tried} is a folder (name a run under --results, or give its folder)")


def load_run(run: Run, name: str | None = None) -> RunMetrics:
    """The run's trained foraging seeds (each ``train/seed_N`` with at least one update in its metrics), in seed
    order; one line of error for a run with none."""
    folders = sorted((p for p in run.results.glob(training_folder("*")) if p.is_dir() and is_seed(p.name)),
                     key=lambda p: job_order(p.name))
    metrics = {p.name: read_metrics(Job(p.name, p)) for p in folders}
    seeds = {seed: df for seed, df in metrics.items() if df is not None and not df.empty}
    if not seeds:
        raise ValueError(f"run {name or run.name} has no trained seed: no {run.path(training_folder('seed_N'))}/"
                         "metrics.parquet with an update yet (policy recipes such as homing are not compared)")
    return RunMetrics(name or run.name, run.results, seeds)


def load_runs(wanted: Sequence[str], results_root: Path = RESULTS_ROOT) -> list[RunMetrics]:
    """Every run named, read before anything is drawn or written; two folders of one name (two results roots) are
    told apart as ``name (2)``."""
    found = [resolve_run(where, results_root) for where in wanted]
    names = [r.name for r in found]
    return [load_run(run, run.name if names.count(run.name) == 1 else f"{run.name} ({i + 1})")
            for i, run in enumerate(found)]


def seed_curve(metrics: pd.DataFrame, metric: str) -> pd.Series:
    """One seed's ``metric`` against env steps, smoothed as watch smooths the return (:func:`efish.watch.smoothed`):
    only the updates with a finite value."""
    return smoothed(metrics.set_index("env_steps")[metric].astype(float))


def mean_curve(curves: Sequence[pd.Series]) -> pd.Series:
    """The mean of seeds' curves over the env steps all of them reached: each curve is interpolated linearly onto
    the others' env steps inside its own range (seeds of one run usually share their env steps, so nothing moves).

    >>> a = pd.Series([0.0, 2.0, 4.0], index=[100, 200, 300])
    >>> mean_curve([a, pd.Series([2.0, 6.0], index=[100, 300])]).tolist()
    [1.0, 3.0, 5.0]
    """
    curves = [c for c in curves if len(c)]
    if not curves:
        return pd.Series(dtype=float)
    table = pd.concat(curves, axis=1, keys=range(len(curves))).sort_index()
    return table.interpolate(method="index", limit_area="inside").dropna().mean(axis=1)


def t_interval(values: Sequence[float], level: float = LEVEL) -> tuple[float, float, float]:
    """(mean, low, high): the mean of ``values`` with its t interval at ``level`` (n - 1 degrees of freedom); the
    interval is NaN with fewer than two values, everything NaN with none.

    >>> [round(v, 3) for v in t_interval([1.0, 2.0, 3.0])]
    [2.0, -0.484, 4.484]
    """
    from scipy import stats

    y = np.asarray(values, dtype=float)
    if y.size == 0:
        return math.nan, math.nan, math.nan
    mean = float(y.mean())
    if y.size < 2:
        return mean, math.nan, math.nan
    half = float(stats.t.ppf(0.5 + level / 2, y.size - 1)) * float(y.std(ddof=1)) / math.sqrt(y.size)
    return mean, mean - half, mean + half


def metric_names(runs: Sequence[RunMetrics]) -> list[str]:
    """The metrics any run's seeds log (:func:`efish.watch.curve_columns`: every numeric column but the x axis and
    the bookkeeping), the return first."""
    columns = curve_columns({f"{run.name}/{seed}": df for run in runs for seed, df in run.seeds.items()})
    return sorted(columns, key=lambda c: c != RETURN)


def summary(runs: Sequence[RunMetrics], metrics: Sequence[str], level: float = LEVEL) -> pd.DataFrame:
    """One row per run x metric it logs: ``seeds`` (those with a finite value), ``final_mean`` (the mean over them of
    each seed's final value: the mean of its last RETURN_WINDOW finite values), ``ci_low``, ``ci_high`` (the t
    interval over seeds at ``level``; NaN with one seed) and ``env_steps`` (what the run's seeds reached)."""
    rows = []
    for run in runs:
        for metric in metrics:
            finals = [window_mean(df[metric]) for df in run.seeds.values() if metric in df.columns]
            if not finals:
                continue  # a metric this run does not log: noted, not a row
            values = [v for v in finals if math.isfinite(v)]
            mean, low, high = t_interval(values, level)
            rows.append({"run": run.name, "metric": metric, "seeds": len(values), "final_mean": mean,
                         "ci_low": low, "ci_high": high, "env_steps": run.env_steps})
    return pd.DataFrame(rows, columns=list(COLUMNS))


def notes(runs: Sequence[RunMetrics], metrics: Sequence[str], table: pd.DataFrame) -> list[str]:
    """One line for each thing the table and figure do not show alike for every run: a metric only some runs log,
    a run with one seed (no interval), a metric with no finite value in a run, seeds that end at other env steps."""
    lines = []
    for metric in metrics:
        have = [run.name for run in runs if run.has(metric)]
        if len(have) < len(runs):
            lacking = [run.name for run in runs if run.name not in have]
            lines.append(f"{metric}: logged by {', '.join(have)} only (not {', '.join(lacking)}): drawn and "
                         "summarised for those")
    for run in runs:
        if len(run.seeds) == 1:
            lines.append(f"{run.name}: one trained seed ({next(iter(run.seeds))}): no interval over seeds")
        empty = table.loc[(table["run"] == run.name) & (table["seeds"] == 0), "metric"].tolist()
        if empty:
            lines.append(f"{run.name}: no seed has a finite {', '.join(empty)} yet (a return needs an episode "
                         "to end): final_mean NaN, no curve")
        ends = sorted({int(df["env_steps"].iloc[-1]) for df in run.seeds.values()})
        if len(ends) > 1:
            lines.append(f"{run.name}: its seeds end at {ends[0]:,} to {ends[-1]:,} env steps (one still training?): "
                         "each seed's final value is at its own end, env_steps the fewest")
    return lines


def check_outputs(out: Path | None, plot: Path | None) -> None:
    """One line of error for an output the command cannot write, before anything is read."""
    if out is not None and out.suffix and out.suffix not in TABLE_SUFFIXES:
        raise ValueError(f"--out {out}: the table is written as {' or '.join(TABLE_SUFFIXES)} (or name a folder)")
    if plot is not None and plot.suffix != ".png":
        raise ValueError(f"--plot {plot}: give a .png (the .pdf is written beside it)")


def write_table(table: pd.DataFrame, out: Path) -> Path:
    """The table as Parquet or CSV by ``out``'s suffix, or ``out/compare_runs.parquet`` for a folder; atomically."""
    return write_table_file(table, out if out.suffix else out / f"{TABLE_NAME}.parquet")


def plot_runs(runs: Sequence[RunMetrics], metrics: Sequence[str], path: Path, title: str) -> list[Path]:
    """One panel per metric (the return first) against env steps, one colour per run: each seed's smoothed curve
    thin, the run's mean over seeds thick; a metric only some runs log says so in its panel's title. Writes
    ``path`` (.png) and the .pdf beside it (:func:`efish.figures.render.save_figure`)."""
    from matplotlib.lines import Line2D
    from matplotlib.ticker import FuncFormatter

    from .figures.render import save_figure
    from .figures.style import missing, panel_style

    per_row = min(PANELS_PER_ROW, len(metrics))
    rows = math.ceil(len(metrics) / per_row)
    colours = {run.name: f"C{i % 10}" for i, run in enumerate(runs)}
    with panel_style() as plt:
        fig, axes = plt.subplots(rows, per_row, squeeze=False, layout="constrained",
                                 figsize=(2.8 * per_row, 2.3 * rows + 0.5))
        for ax, metric in zip(axes.ravel(), metrics, strict=False):
            for run in runs:
                curves = list(run.curves(metric).values())
                if len(curves) > 1:
                    for curve in curves:
                        ax.plot(curve.index, curve.to_numpy(), lw=0.6, alpha=0.4, color=colours[run.name])
                mean = mean_curve(curves)
                ax.plot(mean.index, mean.to_numpy(), lw=2, color=colours[run.name],
                        marker="o" if len(mean) == 1 else "")  # one update: a point
            have = [run.name for run in runs if run.has(metric)]
            only = "" if len(have) == len(runs) else f" ({', '.join(have)} only)"
            ax.set_title(f"{CURVE_LABELS.get(metric, metric)}{only}", fontsize=7)
            ax.set_xlabel("env steps")
            ax.xaxis.set_major_formatter(FuncFormatter(steps_label))
            if not any(len(line.get_xdata()) for line in ax.lines):
                missing(ax, "no finite value in any seed")
        for ax in axes.ravel()[len(metrics):]:
            ax.axis("off")
        handles = [Line2D([], [], color=colours[run.name], lw=2,
                          label=f"{run.name} ({len(run.seeds)} seed{'s' * (len(run.seeds) != 1)})") for run in runs]
        fig.legend(handles=handles, loc="outside lower center", ncols=min(len(runs), 4), fontsize=7, frameon=False)
        fig.suptitle(title, fontsize=9)
        written = save_figure(fig, path.with_suffix(""))
        plt.close(fig)
    return written


def compare_runs(wanted: Sequence[str], results_root: Path = RESULTS_ROOT, out: Path | None = None,
                 plot: Path | None = None, show: Callable[[str], None] = print) -> pd.DataFrame:
    """The command: read every run, print the table (and the notes), then write the table (``out``) and the
    figure (``plot``) where asked. Returns the table."""
    if not wanted:
        raise ValueError("compare-runs needs a run: name one or more (run names under --results, or folders), or "
                         "give --sweep")
    check_outputs(out, plot)
    runs = load_runs(wanted, results_root)
    metrics = metric_names(runs)
    table = summary(runs, metrics)
    show(f"final value per run: the mean over seeds of each seed's last {RETURN_WINDOW} finite values, with a "
         f"{LEVEL:.0%} t interval over seeds")
    show(table.to_string(index=False, float_format=lambda v: f"{v:.4g}"))
    for line in notes(runs, metrics, table):
        show(f"note: {line}")
    written = []
    if out is not None:
        written.append(write_table(table, out))
    if plot is not None:
        title = (f"Training curves of {', '.join(run.name for run in runs)} (smoothed over {RETURN_WINDOW} updates; "
                 f"{time.strftime('%Y-%m-%d %H:%M')})")
        written += plot_runs(runs, metrics, plot, title)
    if written:
        show(f"wrote {', '.join(map(str, written))}")
    return table
