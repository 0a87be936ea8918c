"""Fault injection: a writer that fails half-way (a full disk) leaves no half-written or mixed outputs."""

from __future__ import annotations

import errno

import pandas as pd
import pyarrow.parquet as pq
import pytest
import torch

from efish.config import compose
from efish.io import atomic_path, write_text_atomic
from efish.rl import train as train_module
from efish.rl.train import CHECKPOINT, METRICS, train
from efish.rollout.tables import write_tables

from ..helpers import cfg_with
from .test_kill_and_resume import TINY


def disk_full_after(n_bytes: int):
    """A writer that writes ``n_bytes`` of garbage to its target, then fails as a full disk does."""
    def write(_obj, target, *args, **kwargs):
        with open(target, "wb") as f:
            f.write(b"\0" * n_bytes)
        raise OSError(errno.ENOSPC, "No space left on device")
    return write


def tables(n: int) -> dict[str, pd.DataFrame]:
    from efish.rollout.run import run_episodes

    from ..rollout.test_termination import WaitThenGo

    return run_episodes(cfg_with("env.episode_steps=3", "scale=smoke"), WaitThenGo(), n, seed=n)


def snapshot(folder):
    return {p.name: p.read_bytes() for p in folder.iterdir()}


@pytest.mark.parametrize("fail_on", [1, 2, 3])  # the first, second or third of the three tables
def test_a_failing_table_write_leaves_the_previous_tables_untouched(tmp_path, monkeypatch, fail_on):
    write_tables(tables(1), tmp_path)
    before = snapshot(tmp_path)
    calls = {"n": 0}
    real = pq.write_table

    def flaky(table, where, *args, **kwargs):
        calls["n"] += 1
        if calls["n"] == fail_on:
            return disk_full_after(100)(table, where)
        return real(table, where, *args, **kwargs)

    monkeypatch.setattr(pq, "write_table", flaky)
    with pytest.raises(OSError, match="No space left"):
        write_tables(tables(2), tmp_path)
    assert snapshot(tmp_path) == before  # old tables intact, no new one beside them, no temporaries


def test_a_failing_checkpoint_write_keeps_the_last_good_checkpoint(tmp_path, monkeypatch):
    cfg = compose(TINY[:-1] + ["train.total_steps=40"])
    train(cfg, tmp_path)
    good = (tmp_path / CHECKPOINT).read_bytes()
    monkeypatch.setattr(torch, "save", disk_full_after(500))
    with pytest.raises(OSError, match="No space left"):
        train(compose(TINY[:-1] + ["train.total_steps=80"]), tmp_path)
    assert (tmp_path / CHECKPOINT).read_bytes() == good
    assert not [p for p in tmp_path.iterdir() if p.name.startswith(".")]


def test_a_failing_metrics_write_keeps_the_previous_metrics(tmp_path, monkeypatch):
    train(compose(TINY[:-1] + ["train.total_steps=40"]), tmp_path)
    good = (tmp_path / METRICS).read_bytes()
    monkeypatch.setattr(pd.DataFrame, "to_parquet", lambda self, target, **kw: disk_full_after(50)(self, target))
    with pytest.raises(OSError, match="No space left"):
        train_module.write_metrics(tmp_path / METRICS, [{"update": 1}])
    assert (tmp_path / METRICS).read_bytes() == good


def test_a_failing_text_write_leaves_no_file(tmp_path, monkeypatch):
    target = tmp_path / "provenance.json"
    monkeypatch.setattr("pathlib.Path.write_text", lambda self, text: disk_full_after(10)(text, self))
    with pytest.raises(OSError):
        write_text_atomic(target, "{}")
    assert list(tmp_path.iterdir()) == []
    with atomic_path(target) as tmp:  # and the same path still works once the disk has room
        tmp.write_bytes(b"{}")
    assert target.read_bytes() == b"{}"
