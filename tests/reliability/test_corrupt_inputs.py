"""Fault injection: truncated or foreign inputs give one clear line, exit code 2, and no partial output."""

from __future__ import annotations

import subprocess
import sys

import pandas as pd
import pytest

from efish.config import compose
from efish.rl.train import CHECKPOINT, FINAL, METRICS, train

from .test_kill_and_resume import TINY


def efish(*args: str) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-m", "efish", *args], capture_output=True, text=True, timeout=300)


def assert_one_line_error(result: subprocess.CompletedProcess, needle: str) -> None:
    assert result.returncode == 2, result.stderr[-2000:]
    lines = result.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("efish: error:") and needle in lines[0], result.stderr


def files(folder):
    return sorted(p.name for p in folder.rglob("*")) if folder.exists() else []


@pytest.fixture(scope="module")
def trained(tmp_path_factory):
    folder = tmp_path_factory.mktemp("trained")
    train(compose(TINY[:-1] + ["train.total_steps=40"]), folder)
    return folder


@pytest.mark.parametrize("damage", ["truncate", "garbage", "empty"])
def test_a_damaged_checkpoint_stops_training_in_one_line(trained, tmp_path, damage):
    out = tmp_path / "run"
    out.mkdir()
    data = (trained / CHECKPOINT).read_bytes()
    (out / CHECKPOINT).write_bytes({"truncate": data[: len(data) // 3], "garbage": b"not a checkpoint" * 100,
                                    "empty": b""}[damage])
    result = efish("train", *TINY[:-1], "train.total_steps=80", "--out", str(out))
    assert_one_line_error(result, "cannot read checkpoint")
    assert files(out) == [CHECKPOINT]  # nothing written beside it


def test_a_damaged_policy_stops_an_assay_before_any_table(trained, tmp_path):
    bad = tmp_path / "policy" / FINAL
    bad.parent.mkdir()
    bad.write_bytes((trained / FINAL).read_bytes()[:1000])
    out = tmp_path / "assay"
    result = efish("assay", "assay=homing", "scale=smoke", "--policy", str(bad.parent), "--out", str(out))
    assert_one_line_error(result, "cannot load a policy")
    assert files(out) == []


@pytest.mark.parametrize("damage", ["truncate", "garbage"])
def test_a_damaged_episodes_table_stops_selection_in_one_line(tmp_path, damage):
    good = tmp_path / "seed_1" / "episodes.parquet"
    good.parent.mkdir()
    pd.DataFrame({"episode": [0, 0], "agent": [0, 1], "size": [0.2, 0.8], "food_eaten": [1, 3]}).to_parquet(good)
    bad = tmp_path / "seed_2" / "episodes.parquet"
    bad.parent.mkdir()
    bad.write_bytes(good.read_bytes()[:40] if damage == "truncate" else b"PAR1" + b"\x00" * 64)
    out = tmp_path / "selection"
    result = efish("select", "--episodes", str(good), str(bad), "--out", str(out))
    assert_one_line_error(result, f"cannot read {bad}")
    assert files(out) == []


def test_a_damaged_table_stops_a_panel_in_one_line(tmp_path):
    from efish.figures.registry import PANELS

    results, out = tmp_path / "results", tmp_path / "figures"
    for path in PANELS["fig3/M"].tables.values():  # every input (its assays' conditions too) present, all damaged
        table = results / path
        table.parent.mkdir(parents=True, exist_ok=True)
        table.write_bytes(b"PAR1 truncated")
    result = efish("figure", "fig3/M", "--results", str(results), "--out", str(out))
    assert_one_line_error(result, "cannot read")
    assert files(out) == []


def test_a_finished_run_with_a_damaged_metrics_table_is_rewritten(trained, tmp_path):
    out = tmp_path / "run"
    out.mkdir()
    (out / CHECKPOINT).write_bytes((trained / CHECKPOINT).read_bytes())
    (out / METRICS).write_bytes(b"PAR1 half a table")
    result = efish("train", *TINY[:-1], "train.total_steps=40", "--out", str(out))
    assert result.returncode == 0, result.stderr[-2000:]
    assert len(pd.read_parquet(out / METRICS)) == 1 and (out / FINAL).exists()
