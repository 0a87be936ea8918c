"""Live training logs: the sinks ``train.loggers`` names, each fed one metrics row per update as it is made
(docs/methods/training.md#live-logs).

``metrics.parquet`` (written by :func:`efish.rl.train.train`) is the table of record; these sinks are for
watching a run: ``csv`` appends ``metrics.csv`` (flushed each update, so ``tail -f`` follows it) and
``tensorboard`` writes event files under ``tensorboard/`` for ``tensorboard --logdir results/<run>/train``. A sink
is opened after a checkpoint is restored, with the rows the checkpoint carries, so a resumed run logs each update
once: the CSV is rewritten from those rows and TensorBoard purges the events a killed run wrote past them.
"""

from __future__ import annotations

import csv
import importlib.util
import math
import shutil
from collections.abc import Callable
from pathlib import Path
from typing import IO, Protocol

from ..io import atomic_path

CSV_FILE = "metrics.csv"
TENSORBOARD_FOLDER = "tensorboard"
STEP = "env_steps"  # the x axis of the TensorBoard curves: comparable between runs of other rollout sizes
POSITION = ("update", "env_steps", "total_updates")  # where a row sits in the run, not a metric to plot
EXTRA = {"tensorboard": "tensorboard"}  # sink -> the package it needs, named as the efish extra installing it


class MetricsLogger(Protocol):
    """A sink of training metrics: one :meth:`log` per update, :meth:`close` at the end."""

    def log(self, row: dict) -> None:
        """Record one update's metrics row (the keys of :func:`efish.rl.train.train`'s rows)."""

    def close(self) -> None:
        """Flush and release the sink."""


class CsvLogger:
    """``metrics.csv``: one row per update, its header the first row's keys, flushed after every row."""

    def __init__(self, path: Path, rows: list[dict]):
        self.fields = list(rows[0]) if rows else None
        # the checkpoint's rows replace the file at once: rows a killed run appended past them go
        with atomic_path(path) as tmp, open(tmp, "w", newline="") as f:
            if rows:
                writer = self._writer(f)
                writer.writeheader()
                writer.writerows(rows)
        self.file: IO[str] = open(path, "a", newline="")  # closed by close()
        self.writer = self._writer(self.file) if self.fields else None

    def _writer(self, f: IO[str]) -> csv.DictWriter:
        # a CSV cannot grow a column mid-file; every row of a run has the same keys, metrics.parquet all of them
        return csv.DictWriter(f, self.fields, extrasaction="ignore")

    def log(self, row: dict) -> None:
        if self.writer is None:  # the run's first row fixes the header
            self.fields = list(row)
            self.writer = self._writer(self.file)
            self.writer.writeheader()
        self.writer.writerow(row)
        self.file.flush()

    def close(self) -> None:
        self.file.close()


class TensorBoardLogger:
    """``tensorboard/``: each finite metric of a row as a scalar of its column's name at the row's env steps."""

    def __init__(self, folder: Path, rows: list[dict]):
        from torch.utils.tensorboard import SummaryWriter

        if not rows:  # a fresh run (or --restart): an earlier run's curves would mix with its own
            shutil.rmtree(folder, ignore_errors=True)
        # purge_step: TensorBoard drops the events at or past it that earlier files hold (a killed run's updates
        # after its last checkpoint, logged again now)
        purge = rows[-1][STEP] + 1 if rows else None
        self.writer = SummaryWriter(str(folder), purge_step=purge)

    def log(self, row: dict) -> None:
        for key, value in row.items():
            # NaN (no episode ended this update) is left out: a gap reads better than a point at NaN
            if key not in POSITION and isinstance(value, (int, float)) and math.isfinite(value):
                self.writer.add_scalar(key, value, global_step=row[STEP])
        self.writer.flush()  # each update, so a watcher sees it now, not after the writer's two minutes

    def close(self) -> None:
        self.writer.close()


#: Sink name -> how it opens in a seed's folder, given the rows a resumed run starts from.
SINKS: dict[str, Callable[[Path, list[dict]], MetricsLogger]] = {
    "csv": lambda out, rows: CsvLogger(out / CSV_FILE, rows),
    "tensorboard": lambda out, rows: TensorBoardLogger(out / TENSORBOARD_FOLDER, rows),
}


def installed(package: str) -> bool:
    """Whether ``package`` can be imported here (without importing it)."""
    return importlib.util.find_spec(package) is not None


def check_loggers(names: list[str]) -> None:
    """One clear error for a sink that cannot run here (unknown, or its package missing): called before training
    starts, so a run never stops at its first update for want of a logger."""
    for name in names:
        if name not in SINKS:
            raise ValueError(f"unknown logger {name!r} in train.loggers: choose any of {', '.join(SINKS)}")
        if name in EXTRA and not installed(EXTRA[name]):
            raise ValueError(f"train.loggers names {name} but the {EXTRA[name]} package is not installed: "
                             f"pip install 'efish[{name}]' (or drop it from train.loggers)")


class Loggers:
    """The sinks of one seed as one: a row goes to each; a context manager that closes them all, also when
    training fails, so the CSV is complete up to the last update and TensorBoard's writer thread stops."""

    def __init__(self, names: list[str], out: Path, rows: list[dict]):
        check_loggers(names)
        self.sinks: list[MetricsLogger] = []
        try:
            for name in dict.fromkeys(names):  # a name given twice opens one sink
                self.sinks.append(SINKS[name](out, rows))
        except BaseException:
            self.close()
            raise

    def log(self, row: dict) -> None:
        for sink in self.sinks:
            sink.log(row)

    def close(self) -> None:
        for sink in self.sinks:
            sink.close()

    def __enter__(self) -> Loggers:
        return self

    def __exit__(self, *exc) -> None:
        self.close()
