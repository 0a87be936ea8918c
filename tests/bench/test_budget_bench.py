"""``efish bench budget``: a run stops when its time is spent; returns and options follow the metrics."""

import math

import pandas as pd
import pytest

from efish.bench.budget import format_budget, options, return_at, steps_at, train_for
from efish.config import compose


def _run(returns, hidden=64, seed=1):
    """A synthetic run: one update per second, 100 env steps each."""
    n = len(returns)
    return pd.DataFrame({"wall_s": [float(i + 1) for i in range(n)], "env_steps": [100 * (i + 1) for i in range(n)],
                         "episode_return": returns, "hidden": hidden, "seed": seed})


def test_return_at_averages_the_last_updates_with_an_ended_episode_by_that_time():
    run = _run([1.0, math.nan, 3.0, 5.0, 7.0, 9.0, 11.0])
    assert return_at(run, 4.0, window=2) == pytest.approx(4.0)   # updates 3 and 4; update 2 ended no episode
    assert return_at(run, 7.0, window=3) == pytest.approx(9.0)
    assert math.isnan(return_at(run, 0.5))
    assert steps_at(run, 4.5) == 400 and steps_at(run, 0.5) == 0


def _table(rows):
    return pd.DataFrame(rows, columns=["hidden", "seed", "fraction", "wall_s", "env_steps", "episode_return"])


def test_options_compare_one_long_seed_the_best_of_short_seeds_and_a_wider_net():
    table = _table([(64, 1, 0.5, 30, 500, 1.0), (64, 1, 1.0, 60, 1000, 2.0),
                    (64, 2, 0.5, 30, 500, 4.0), (64, 2, 1.0, 60, 1000, 3.0),
                    (128, 1, 0.5, 30, 250, 0.0), (128, 1, 1.0, 60, 500, 1.0),
                    (128, 2, 0.5, 30, 250, 0.0), (128, 2, 1.0, 60, 500, 0.0)])
    got = options(table)
    assert list(got["episode_return"]) == [4.0, 2.5, 0.5]  # best of 2 half-runs, mean of long runs, wider mean
    assert got["option"][0].startswith("more seeds") and got["option"][2].startswith("wider: width 128")
    table.attrs.update(minutes=1, seeds=2, jobs=2, cpu="test CPU")
    text = format_budget(table)
    assert "test CPU" in text and text.index("more seeds") < text.index("more env steps")


def test_a_run_stops_at_the_first_update_past_its_time():
    cfg = compose(["scale=smoke", "env.n_agents=2", "train.num_envs=2", "train.chunk=10", "train.rollout_steps=20"])
    run = train_for(cfg, hidden=8, seed=3, seconds=0.0)
    assert len(run) == 1 and run["env_steps"].iloc[0] == 40
    assert set(run["hidden"]) == {8} and set(run["seed"]) == {3}


def test_bad_budgets_are_one_clear_error():
    from efish.bench.budget import bench_budget

    with pytest.raises(ValueError, match="minutes > 0"):
        bench_budget(compose(["scale=smoke"]), (64,), seeds=2, minutes=0)


def test_efish_bench_budget_flags_override_the_config_fields_and_are_recorded(tmp_path, monkeypatch, capsys):
    from efish.bench import budget
    from efish.cli import main

    seen = {}

    def fake(cfg, progress=None):
        seen["sizes"] = budget.budget_sizes(cfg)
        table = _table([(8, 1, 1.0, 30, 500, 1.0)])
        table.attrs.update(minutes=0.5, seeds=1, jobs=1, cpu="test CPU")
        return table

    monkeypatch.setattr(budget, "bench_budget", fake)
    assert main(["bench", "budget", "scale=smoke", "bench.budget_seeds=1", "--minutes", "0.5", "--hidden", "8",
                 "--out", str(tmp_path)]) == 0
    assert seen["sizes"] == ((8,), 1, 0.5, 2)  # jobs: the config's default
    assert "budget_minutes: 0.5" in (tmp_path / "config.yaml").read_text()
    assert "1 runs of 0.5 min" in capsys.readouterr().err
    assert main(["bench", "budget", "scale=smoke", "--seeds", "0"]) == 2
    assert capsys.readouterr().err.startswith("efish: error: bench budget needs minutes > 0, seeds >= 1")
