"""``efish compare-runs``: several runs' final values (mean over seeds, t interval) computed by hand, its figure, its
one-line errors, the recipe folders left out, and a sweep's points named as compare-claims names them."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest
from scipy import stats

from efish import compare_runs as compare_module
from efish.cli import main
from efish.compare_runs import COLUMNS, mean_curve, seed_curve
from efish.layout import Run, seed_name, training_file
from efish.watch import RETURN_WINDOW

UPDATES = 30
STEPS_PER_UPDATE = 100


def metrics_table(returns: np.ndarray, steps: int = STEPS_PER_UPDATE, **extra) -> pd.DataFrame:
    """A job's metrics as training writes them (a row per update), with ``returns`` as its episode returns."""
    u = np.arange(1, len(returns) + 1)
    return pd.DataFrame({"update": u, "total_updates": len(returns), "env_steps": u * steps, "wall_s": u * 0.5,
                         "episode_return": returns, "entropy": 4.2 - 0.01 * u, "approx_kl": 1e-3,
                         "env_steps_per_s": 500.0, **extra})


def write_job(root, run: str, job: str, table: pd.DataFrame) -> None:
    path = Run(run, results_root=root).path(training_file(job, "metrics.parquet"))
    path.parent.mkdir(parents=True, exist_ok=True)
    table.to_parquet(path, index=False)


def returns_towards(level: float, rng) -> np.ndarray:
    """A return rising to ``level`` over the first half of training, then level there, plus noise; NaN where no
    episode ended (every fourth update)."""
    returns = level * np.minimum(1, np.arange(1, UPDATES + 1) / (UPDATES / 2)) + rng.normal(0, 3, UPDATES)
    returns[::4] = np.nan
    return returns


@pytest.fixture()
def results(tmp_path):
    """Run A: 3 seeds whose return ends at 100 + noise (and a reward term only A logs) plus a homing recipe
    folder; run B: 3 seeds at 50 + noise; run C: one seed at 75 + noise; run D: a homing folder and no seed; run E:
    a seed folder without metrics. ``returns`` holds each seed's returns."""
    rng = np.random.default_rng(7)
    root = tmp_path / "results"
    returns = {}
    for run, level, seeds in (("A", 100.0, (1, 2, 3)), ("B", 50.0, (2, 5, 10)), ("C", 75.0, (1,))):
        for seed in seeds:
            returns[run, seed] = returns_towards(level, rng)
            extra = {"reward_food": rng.normal(1, 0.1, UPDATES)} if run == "A" else {}
            write_job(root, run, seed_name(seed), metrics_table(returns[run, seed], **extra))
    write_job(root, "A", "homing", metrics_table(np.full(10, 5.0), homing_success=np.ones(10)))
    write_job(root, "D", "homing", metrics_table(np.full(10, 5.0)))
    root.joinpath("E", "train", "seed_1").mkdir(parents=True)  # a seed not started: no metrics yet
    return root, returns


def by_hand(finals: list[float]) -> tuple[float, float, float]:
    """The mean of the seeds' final values and its 95% t interval, as scipy gives it."""
    y = np.array(finals)
    if y.size == 1:
        return float(y[0]), np.nan, np.nan
    low, high = stats.t.interval(0.95, y.size - 1, loc=y.mean(), scale=stats.sem(y))
    return float(y.mean()), float(low), float(high)


def last_window(values: np.ndarray) -> float:
    finite = values[np.isfinite(values)]
    return float(finite[-RETURN_WINDOW:].mean())


def test_the_table_is_each_runs_mean_of_its_seeds_final_values_with_a_t_interval(results, tmp_path, capsys):
    root, returns = results
    out = tmp_path / "compare" / "compare_runs.csv"
    assert main(["compare-runs", "A", "B", "C", "--results", str(root), "--out", str(out)]) == 0
    printed = capsys.readouterr().out
    table = pd.read_csv(out)
    assert tuple(table.columns) == COLUMNS
    assert table["run"].unique().tolist() == ["A", "B", "C"]
    rows = table[table["metric"] == "episode_return"].set_index("run")
    for run, seeds in (("A", (1, 2, 3)), ("B", (2, 5, 10)), ("C", (1,))):
        mean, low, high = by_hand([last_window(returns[run, s]) for s in seeds])
        row = rows.loc[run]
        assert row["seeds"] == len(seeds) and row["env_steps"] == UPDATES * STEPS_PER_UPDATE
        assert row["final_mean"] == pytest.approx(mean, rel=1e-9)
        if len(seeds) > 1:
            assert (row["ci_low"], row["ci_high"]) == (pytest.approx(low, rel=1e-9), pytest.approx(high, rel=1e-9))
        else:  # one seed: no interval
            assert np.isnan(row["ci_low"]) and np.isnan(row["ci_high"]) and np.isnan(low)
    assert 95 < rows.loc["A", "final_mean"] < 105 and 45 < rows.loc["B", "final_mean"] < 55
    assert rows.loc["B", "ci_high"] < rows.loc["A", "ci_low"]
    # the return first, then the other metrics; a metric a run does not log is no row of that run
    assert table.groupby("run")["metric"].first().eq("episode_return").all()
    assert set(table.loc[table["metric"] == "reward_food", "run"]) == {"A"}
    lines = printed.splitlines()
    assert f"last {RETURN_WINDOW} finite values" in lines[0] and lines[1].split() == list(COLUMNS)
    assert "note: reward_food: logged by A only (not B, C)" in printed
    assert "note: C: one trained seed (seed_1): no interval over seeds" in printed
    assert f"wrote {out}" in printed


def test_recipe_folders_are_left_out(results, tmp_path):
    root, _ = results
    out = tmp_path / "table.parquet"
    assert main(["compare-runs", "A", "--results", str(root), "--out", str(out)]) == 0
    table = pd.read_parquet(out)
    assert "homing_success" not in set(table["metric"])  # a metric only the homing folder logs
    assert table["seeds"].max() == 3


def test_the_plot_is_written_as_png_and_pdf_titled_with_the_runs(results, tmp_path, capsys, monkeypatch):
    root, _ = results
    drawn = {}
    real = compare_module.plot_runs

    def spy(runs, metrics, path, title):
        drawn.update(metrics=list(metrics), title=title, runs=[r.name for r in runs])
        return real(runs, metrics, path, title)

    monkeypatch.setattr(compare_module, "plot_runs", spy)
    png = tmp_path / "figures" / "curves.png"
    assert main(["compare-runs", "A", "B", "C", "--results", str(root), "--plot", str(png)]) == 0
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n" and png.stat().st_size > 10_000
    assert png.with_suffix(".pdf").stat().st_size > 1_000
    assert drawn["runs"] == ["A", "B", "C"] and drawn["metrics"][0] == "episode_return"
    assert "reward_food" in drawn["metrics"] and "env_steps" not in drawn["metrics"]
    assert drawn["title"].startswith(f"Training curves of A, B, C (smoothed over {RETURN_WINDOW} updates; 20")
    assert f"wrote {png}, {png.with_suffix('.pdf')}" in capsys.readouterr().out


@pytest.mark.parametrize("runs, message", [
    (["A", "D"], "run D has no trained seed"),  # only a recipe folder
    (["A", "E"], "run E has no trained seed"),  # a seed folder without metrics
    (["A", "nope"], "no run 'nope'"),
    ([], "compare-runs needs a run"),
])
def test_a_run_without_a_trained_seed_is_one_line_exit_2_and_nothing_written(results, tmp_path, capsys, runs,
                                                                               message):
    root, _ = results
    out, png = tmp_path / "out" / "t.csv", tmp_path / "out" / "curves.png"
    assert main(["compare-runs", *runs, "--results", str(root), "--out", str(out), "--plot", str(png)]) == 2
    captured = capsys.readouterr()
    assert captured.err.count("\n") == 1 and captured.err.startswith(f"efish: error: {message}"), captured.err
    assert captured.out == "" and not (tmp_path / "out").exists()


def test_a_wrong_suffix_is_refused_before_anything_is_read(tmp_path, capsys):
    assert main(["compare-runs", "A", "--results", str(tmp_path), "--out", str(tmp_path / "t.txt")]) == 2
    assert "the table is written as .parquet or .csv" in capsys.readouterr().err
    assert main(["compare-runs", "A", "--results", str(tmp_path), "--plot", str(tmp_path / "c.pdf")]) == 2
    assert "give a .png" in capsys.readouterr().err


def test_a_run_is_a_name_under_results_or_a_folder_and_an_out_folder_gets_the_parquet(results, tmp_path, capsys):
    root, _ = results
    assert main(["compare-runs", str(root / "A"), "B", "--results", str(root), "--out", str(tmp_path / "t")]) == 0
    table = pd.read_parquet(tmp_path / "t" / "compare_runs.parquet")
    assert table["run"].unique().tolist() == ["A", "B"]


def test_a_seed_curve_is_watchs_smoothing_and_the_mean_covers_the_steps_every_seed_reached():
    returns = np.array([1.0, np.nan, 3.0, 5.0, 7.0] + [9.0] * 12)
    curve = seed_curve(metrics_table(returns), "episode_return")
    assert curve.index[0] == STEPS_PER_UPDATE and STEPS_PER_UPDATE * 2 not in curve.index  # the NaN update: no point
    assert curve.iloc[:4].tolist() == [1.0, 2.0, 3.0, 4.0]  # fewer than the window at the start
    assert curve.iloc[-1] == pytest.approx(last_window(returns))
    short = pd.Series([0.0, 4.0], index=[100, 300])
    assert mean_curve([curve.iloc[:4], short]).index.tolist() == [100, 300]
    assert mean_curve([curve.iloc[:4], short]).tolist() == [0.5, 3.0]


def test_a_sweeps_points_are_its_runs(tmp_path, capsys):
    """--sweep with --scale and --overrides names the runs the workflow would (efish.sweep.sweep_runs)."""
    from efish.sweep import sweep_runs

    names = sweep_runs("smoke", ["analysis.claims_alpha=0.01"], "train.lr=1e-3,3e-4")
    rng = np.random.default_rng(1)
    for name in names:
        write_job(tmp_path, name, seed_name(1), metrics_table(returns_towards(10.0, rng)))
    assert main(["compare-runs", "--sweep", "train.lr=1e-3,3e-4", "--scale", "smoke", "--overrides",
                 "analysis.claims_alpha=0.01", "--results", str(tmp_path)]) == 0
    printed = capsys.readouterr().out
    assert all(name in printed for name in names) and len(set(names)) == 2


def test_help_cites_its_tutorial_and_the_smoothing_window(capsys):
    with pytest.raises(SystemExit):
        main(["compare-runs", "--help"])
    text = " ".join(capsys.readouterr().out.split())
    assert "docs/tutorials/watch-a-run.md#compare-runs" in text and f"last {RETURN_WINDOW} finite values" in text
