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
from efish.run_plan import RunPlan
from efish.watch import RETURN_WINDOW, SMOOTHED, Job, curve_columns, duration, job_row, read_metrics, task_groups

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


def test_a_run_is_named_by_its_folder_as_well_as_by_its_name(results, capsys):
    by_name = watch_lines(capsys, RUN, "--results", str(results), "--once")
    by_folder = watch_lines(capsys, str(results / RUN), "--once")
    # the same jobs, states and updates (the title's time and each job's age move between the two calls)
    assert [line.split()[:3] for line in by_folder[1:]] == [line.split()[:3] for line in by_name[1:]]
    assert len(by_folder) == len(by_name) > 2


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
    assert (row["state"], row["update"], row["ETA"], row[SMOOTHED]) == ("running", "2/4", "4s", "1.500")
    assert job_row(job, None, now=0.0)["state"] == "not started"


def test_durations_read_at_a_glance():
    assert [duration(s) for s in (42, 185, 7620, float("nan"))] == ["42s", "3m05s", "2h07m", "?"]


def test_a_shipped_scale_counts_every_planned_job_from_the_first_call(tmp_path, capsys):
    """Before any job has started the table lists every seed and every policy recipe the run plan trains, each
    with its updates, so the job count does not grow when a recipe's job starts."""
    (tmp_path / "smoke").mkdir()
    cfg = compose(["scale=smoke", "policy=foraging"]).train
    updates = max(1, cfg.total_steps // (cfg.rollout_steps * cfg.num_envs))
    title, _, *lines = watch_lines(capsys, "smoke", "--results", str(tmp_path), "--once")
    seeds = compose(["scale=smoke"]).scale.seed_numbers()
    recipes = sorted({p for assay in RunPlan.from_config({"scale": "smoke"}).assays
                      for p in RunPlan.from_config({"scale": "smoke"}).assay_policies[assay]} - {"selected"})
    assert recipes, "the smoke scale acts with at least one policy recipe (homing)"
    assert [line.split()[:4] for line in lines[:len(seeds)]] == [[f"seed_{s}", "not", "started", f"0/{updates}"]
                                                                 for s in seeds]
    assert [line.split()[0] for line in lines[len(seeds):]] == recipes
    assert all(line.split()[3] != "0/?" for line in lines), lines  # every recipe's updates from its config
    assert f"0/{len(seeds) + len(recipes)} training jobs finished" in title


def test_the_return_is_smoothed_over_the_last_finite_returns(tmp_path):
    job = Job("seed_1", tmp_path)
    returns = [float(r) for r in range(1, 13)] + [float("nan"), -50.0]  # a bad last update after a good run
    metrics = pd.DataFrame({"update": range(1, 15), "total_updates": 20, "env_steps": range(100, 1500, 100),
                            "episode_return": returns, "entropy": 0.5, "approx_kl": 0.01,
                            "env_steps_per_s": [50.0] * 13 + [5.0]})  # the last update under heavy load
    metrics.to_parquet(tmp_path / "metrics.parquet")
    row = job_row(job, read_metrics(job), now=0.0)
    window = [r for r in returns if r == r][-RETURN_WINDOW:]
    assert row[SMOOTHED] == f"{sum(window) / len(window):.3f}" and row["last return"] == "-50.000"
    assert row["ETA"] == "12s"  # 6 updates x 100 steps at the median 50 steps/s, not the last update's 5


def test_plot_draws_every_metric_with_a_title_and_each_task_on_its_own_axes(results, tmp_path, capsys, monkeypatch):
    drawn = {}
    real = watch_module.plot_curves

    def spy(metrics, path, title=""):
        drawn.update(metrics=metrics, title=title)
        real(metrics, path, title)

    monkeypatch.setattr(watch_module, "plot_curves", spy)
    png = tmp_path / "curves.png"
    watch_lines(capsys, RUN, "--results", str(results), "--once", "--plot", str(png))
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert drawn["title"].startswith(f"{RUN}: training curves (")
    columns = curve_columns(drawn["metrics"])
    for column in ("episode_return", "policy_loss", "value_loss", "explained_variance", "env_steps_per_s",
                   "entropy", "approx_kl", "clip_fraction"):
        assert column in columns, column
    assert not set(columns) & {"update", "env_steps", "wall_s", "total_updates"}
    assert task_groups(["seed_2", "homing", "seed_10", "homing_raycast"]) == {
        "foraging seeds": ["seed_2", "seed_10"], "homing": ["homing"], "homing_raycast": ["homing_raycast"]}
    # a later draw of a homing recipe (scale.homing_seeds) is the same task: on its recipe's axes
    assert task_groups(["homing", "homing_draw_2", "homing_raycast", "homing_raycast_draw_2"]) == {
        "homing": ["homing", "homing_draw_2"], "homing_raycast": ["homing_raycast", "homing_raycast_draw_2"]}


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


def test_a_later_draw_of_a_homing_recipe_plans_its_recipes_updates():
    """train/homing_draw_2 (scale.homing_seeds) is the homing recipe trained again with another seed."""
    from efish.watch import _recipe_updates

    homing = _recipe_updates("laptop", "homing")
    assert homing and _recipe_updates("laptop", "homing_draw_2") == homing
    assert _recipe_updates("laptop", "homing_raycast_draw_3") == _recipe_updates("laptop", "homing_raycast")
    assert _recipe_updates("laptop", "nothing_draw_2") is None
