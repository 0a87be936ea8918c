"""``efish watch``: the table of a run's training jobs, its plot, its live loop and its one-line errors."""

from __future__ import annotations

import re
import shutil

import pandas as pd
import pytest

from efish import watch as watch_module
from efish.cli import main
from efish.config import compose
from efish.layout import Run, seed_name, training_folder
from efish.rl.train import train
from efish.watch import Job, duration, job_row, read_metrics

from .helpers import Killed, kill_at
from .rl.test_train import tiny

RUN = "tiny"


@pytest.fixture(scope="module")
def results(tmp_path_factory):
    """A run with seed 1 finished (2 of 2 updates) and seed 2 stopped at update 1 of 3 (running, to the files)."""
    root = tmp_path_factory.mktemp("results")
    run = Run(RUN, results_root=root)
    train(tiny(2), run.path(training_folder(seed_name(1))))
    with pytest.raises(Killed):
        train(tiny(3), run.path(training_folder(seed_name(2))), progress=kill_at(1))
    return root


def watch_lines(capsys, *args: str) -> list[str]:
    assert main(["watch", *args]) == 0
    return capsys.readouterr().out.splitlines()


def test_once_shows_a_finished_and_a_running_seed_with_their_updates(results, capsys):
    title, header, first, second = watch_lines(capsys, RUN, "--results", str(results), "--once")
    assert title.startswith(f"{RUN}: 1/2 training jobs finished")
    assert header.split()[:4] == ["job", "state", "update", "env"]
    assert re.match(r"\s*seed_1\s+finished\s+2/2\s+80\s", first), first  # 2 arenas x 20 steps per update
    assert re.match(r"\s*seed_2\s+running\s+1/3\s+40\s", second), second


def test_the_eta_is_the_updates_left_at_the_recent_speed(tmp_path):
    job = Job("seed_1", tmp_path)
    metrics = pd.DataFrame({"update": [1, 2], "total_updates": 4, "env_steps": [100, 200],
                            "episode_return": [1.5, float("nan")], "entropy": 0.5, "approx_kl": 0.01,
                            "env_steps_per_s": [40.0, 60.0]})
    metrics.to_parquet(tmp_path / "metrics.parquet")
    row = job_row(job, read_metrics(job), now=0.0)
    # 2 updates of 100 env steps left at 50 env steps/s; the last update ended no episode: the one before's return
    assert (row["state"], row["update"], row["ETA"], row["return"]) == ("running", "2/4", "4s", "1.500")
    assert job_row(job, None, now=0.0)["state"] == "not started"


def test_durations_read_at_a_glance():
    assert [duration(s) for s in (42, 185, 7620, float("nan"))] == ["42s", "3m05s", "2h07m", "?"]


def test_a_shipped_scale_lists_the_seeds_not_started_with_their_updates(tmp_path, capsys):
    (tmp_path / "smoke").mkdir()
    cfg = compose(["scale=smoke", "policy=foraging"]).train
    updates = max(1, cfg.total_steps // (cfg.rollout_steps * cfg.num_envs))
    lines = watch_lines(capsys, "smoke", "--results", str(tmp_path), "--once")[2:]
    seeds = compose(["scale=smoke"]).scale.seed_numbers()
    assert [line.split()[:4] for line in lines] == [[f"seed_{s}", "not", "started", f"0/{updates}"] for s in seeds]


def test_plot_writes_a_png(results, tmp_path, capsys):
    png = tmp_path / "curves.png"
    watch_lines(capsys, RUN, "--results", str(results), "--once", "--plot", str(png))
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


def test_the_live_table_refreshes_until_ctrl_c(results, capsys, monkeypatch):
    def ctrl_c(seconds: float) -> None:
        raise KeyboardInterrupt

    monkeypatch.setattr(watch_module.time, "sleep", ctrl_c)
    lines = watch_lines(capsys, RUN, "--results", str(results), "--interval", "1")  # exit 0, after one table
    assert sum(line.startswith(f"{RUN}:") for line in lines) == 1


def test_the_live_table_stops_when_every_job_is_finished(results, tmp_path, capsys, monkeypatch):
    shutil.copytree(results / RUN / training_folder(seed_name(1)), tmp_path / "done" / training_folder(seed_name(1)))
    monkeypatch.setattr(watch_module.time, "sleep", lambda seconds: pytest.fail("waited for a finished run"))
    assert watch_lines(capsys, "done", "--results", str(tmp_path))[0].startswith("done: 1/1 training jobs finished")


@pytest.mark.parametrize(("make", "args", "message"), [
    (False, [], r"no run folder .*absent"),
    (True, [], r"absent.train.? holds no training jobs"),
    (True, ["--interval", "0"], r"--interval 0 must be above 0 seconds"),
])
def test_bad_input_is_one_line(tmp_path, capsys, make, args, message):
    if make:
        (tmp_path / "absent").mkdir()
    assert main(["watch", "absent", "--results", str(tmp_path), *args]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and re.search(message, err), err
