"""Live training logs: every sink gets each update once, across a resume too; a reader never sees a torn table."""

from __future__ import annotations

import dataclasses
import threading

import numpy as np
import pandas as pd
import pytest

from efish.config import ConfigError, compose
from efish.config.schema import TrainConfig, result_neutral_keys
from efish.io import read_parquet
from efish.rl import loggers
from efish.rl.loggers import CSV_FILE, SINKS, TENSORBOARD_FOLDER
from efish.rl.train import METRICS, train

from ..helpers import Killed, kill_at
from .test_train import tiny

BOTH = "train.loggers=[csv,tensorboard]"


def scalars(out, tag: str) -> tuple[list[int], list[float]]:
    """The steps and values TensorBoard reads for ``tag`` from a seed's event files (a restart's purge applied)."""
    from tensorboard.backend.event_processing.event_accumulator import EventAccumulator

    acc = EventAccumulator(str(out / TENSORBOARD_FOLDER))
    acc.Reload()
    events = acc.Scalars(tag)
    return [e.step for e in events], [e.value for e in events]


def test_every_sink_writes_one_row_per_update(tmp_path):
    train(tiny(3, BOTH), tmp_path)
    table, csv = pd.read_parquet(tmp_path / METRICS), pd.read_csv(tmp_path / CSV_FILE)
    assert list(table["update"]) == list(csv["update"]) == [1, 2, 3] and list(csv.columns) == list(table.columns)
    np.testing.assert_allclose(csv["entropy"], table["entropy"], rtol=1e-12)
    steps, values = scalars(tmp_path, "entropy")
    assert steps == [40, 80, 120]  # keyed by env steps: 2 arenas x 20 steps per update
    np.testing.assert_allclose(values, table["entropy"], rtol=1e-6)  # event files hold float32
    with pytest.raises(KeyError):
        scalars(tmp_path, "update")  # a row's position, not a curve


def test_a_resumed_run_logs_each_update_once(tmp_path):
    with pytest.raises(Killed):  # update 3 is logged, but the last checkpoint is update 2's
        train(tiny(4, BOTH, "train.checkpoint_every=2"), tmp_path, progress=kill_at(3))
    assert list(pd.read_csv(tmp_path / CSV_FILE)["update"]) == [1, 2, 3]
    # the loggers are result-neutral: another list still resumes the checkpoint
    train(tiny(4, "train.loggers=[tensorboard,csv]", "train.checkpoint_every=2"), tmp_path)
    assert list(pd.read_csv(tmp_path / CSV_FILE)["update"]) == [1, 2, 3, 4]
    assert list(pd.read_parquet(tmp_path / METRICS)["update"]) == [1, 2, 3, 4]
    assert scalars(tmp_path, "entropy")[0] == [40, 80, 120, 160]  # the killed run's update 3 purged


def test_a_reader_never_sees_a_torn_metrics_table(tmp_path):
    seen, errors, done = [], [], threading.Event()

    def read() -> None:
        while not done.is_set():
            if (tmp_path / METRICS).exists():
                try:
                    seen.append(len(read_parquet(tmp_path / METRICS)))  # efish's reader, as efish watch's
                except Exception as exc:  # a torn or half-renamed table
                    errors.append(exc)

    reader = threading.Thread(target=read)
    reader.start()
    try:  # one checkpoint, at the end: the table grows by its own writes only
        train(tiny(4, "train.checkpoint_every=4"), tmp_path)
    finally:
        done.set()
        reader.join()
    assert not errors
    assert seen == sorted(seen) and set(seen) == {1, 2, 3, 4}


def test_an_unknown_logger_is_one_line_naming_the_valid_ones():
    with pytest.raises(ConfigError, match=r"^train.loggers=\['csv', 'wandb'\] is not allowed: choose any of csv, "
                                          r"tensorboard$"):
        compose(["train.loggers=[csv,wandb]"])


def test_a_logger_without_its_package_fails_before_training(tmp_path, monkeypatch):
    monkeypatch.setattr(loggers, "installed", lambda package: False)
    with pytest.raises(ValueError, match=r"^train.loggers names tensorboard .* pip install 'efish\[tensorboard\]'"):
        train(tiny(1, BOTH), tmp_path / "seed")
    assert not (tmp_path / "seed").exists()
    train(tiny(1), tmp_path / "seed")  # the default, csv alone, needs nothing more


def test_the_schema_offers_the_sinks_there_are_and_they_cannot_change_a_result():
    field = next(f for f in dataclasses.fields(TrainConfig) if f.name == "loggers")
    assert set(field.metadata["choices"]) == set(SINKS) and field.default_factory() == ["csv"]
    assert "train.loggers" in result_neutral_keys()
