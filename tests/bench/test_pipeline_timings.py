"""``efish bench pipeline``: benchmark files grouped by rule family, sums exact."""

from __future__ import annotations

import pytest

from efish.bench.pipeline import COLUMNS, pipeline_timings

HEADER = "s\th:m:s\tmax_rss\tmax_vms\tmax_uss\tmax_pss\tio_in\tio_out\tmean_load\tcpu_time\n"


def write(path, seconds, rss="100.0"):
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(HEADER + f"{seconds}\t0:00:01\t{rss}\t1\t1\t1\t0\t0\t0\t1\n")


def test_jobs_are_grouped_by_folder_and_summed(tmp_path):
    root = tmp_path / "benchmarks"
    write(root / "train/seed_1.tsv", 10.0, "500")
    write(root / "train/seed_2.tsv", 30.0, "700")
    write(root / "select_seed.tsv", 1.5, "-")  # Snakemake writes '-' when it could not measure
    table = pipeline_timings(tmp_path).set_index("group")
    assert list(table.reset_index().columns) == list(COLUMNS)
    assert table.loc["train", "jobs"] == 2 and table.loc["train", "total_s"] == 40.0
    assert table.loc["train", "max_s"] == 30.0 and table.loc["train", "max_rss_mb"] == 700
    assert table.loc["all", "total_s"] == 41.5 and table.loc["all", "jobs"] == 3
    assert table.index[0] == "train"  # most expensive first


def test_no_benchmarks_is_one_clear_error(tmp_path):
    with pytest.raises(ValueError, match="no Snakemake benchmark files"):
        pipeline_timings(tmp_path)


def test_interleaved_timing_alternates_and_keeps_each_best(monkeypatch):
    """Runs go a, b, a, b (not a, a, b, b), and each function gets the best of its own runs."""
    from efish.bench import timing

    clock = iter([0.0, 5.0, 5.0, 6.0, 6.0, 8.0, 8.0, 8.5])  # a: 5 then 2 s, b: 1 then 0.5 s
    monkeypatch.setattr(timing.time, "perf_counter", lambda: next(clock))
    calls = []
    best = timing.best_times_interleaved([lambda: calls.append("a"), lambda: calls.append("b")], rounds=2,
                                         warmup=False)
    assert calls == ["a", "b", "a", "b"]
    assert best == [2.0, 0.5]
