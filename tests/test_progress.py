"""efish watch's pipeline line: the jobs done from Snakemake's metadata, the total from a dry run that counts the
jobs after seed selection before it has run, the time left from the run's own job times."""

from __future__ import annotations

import base64
import json
import subprocess
from collections import Counter
from pathlib import Path

import pandas as pd
import pytest

from efish.layout import Run
from efish.progress import (
    METADATA,
    PipelineWatch,
    Progress,
    finished_jobs,
    jobs_to_run,
    parse_job_stats,
    pipeline_watch,
    progress,
)

from .helpers import scratch_workflow, smoke_env

STATS = """Building DAG of jobs...
Job stats:
job                 count
----------------  -------
train                   4
top_seed_group         12
all                     1
total                  17

Job stats:
job                 count
----------------  -------
train                   4
total                   5
"""


def test_the_dry_runs_job_stats_are_read_by_rule_without_the_collecting_rule():
    assert parse_job_stats(STATS) == Counter({"train": 4, "top_seed_group": 12})
    assert parse_job_stats("Building DAG of jobs...\nNothing to be done.") == Counter()


def record(work: Path, output: str, rule: str, job: int, start: float, end: float | None, incomplete=False,
           name_max: int = 255) -> None:
    """One of Snakemake's metadata records, at the path Snakemake gives it (urlsafe base64 of the output, cut into
    @-prefixed folders where longer than a file name may be)."""
    b64 = base64.urlsafe_b64encode(output.encode()).decode()
    pieces = [b64[i:i + name_max - 1] for i in range(0, len(b64), name_max - 1)]
    path = work / METADATA / Path(*["@" + p for p in pieces[:-1]], pieces[-1])
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(json.dumps({"rule": rule, "job_hash": job, "starttime": start, "endtime": end,
                                "incomplete": incomplete}))


def made(work: Path, output: str) -> None:
    (work / output).parent.mkdir(parents=True, exist_ok=True)
    (work / output).write_text("x")


def test_finished_jobs_are_the_runs_complete_records_one_row_per_job(tmp_path):
    run = Run("smoke", results_root=tmp_path / "results", figures_root=tmp_path / "figures")
    for name in ("a.parquet", "b.parquet"):  # one job, two outputs: one row, from its first start
        made(tmp_path, f"results/smoke/analysis/{name}")
        record(tmp_path, f"results/smoke/analysis/{name}", "analysis_behaviour", 7, 100.0 + (name == "b.parquet"),
               103.0)
    made(tmp_path, "figures/smoke/fig2/a.png")
    record(tmp_path, "figures/smoke/fig2/a.png", "figure_fig2", 8, 110.0, 114.0)
    long = "results/smoke/" + "deep/" * 60 + "t.parquet"  # a name longer than a file name: cut into folders
    made(tmp_path, long)
    record(tmp_path, long, "assay", 9, 120.0, 150.0, name_max=64)
    record(tmp_path, "results/smoke/seeds/groups/npatch", "top_seed_group", 10, 105.0, 130.0)  # temp(), used
    record(tmp_path, "results/smoke/train/seed_1/final.pt", "train", 11, 10.0, 50.0)  # deleted since
    made(tmp_path, "results/smoke/train/seed_2/final.pt")
    record(tmp_path, "results/smoke/train/seed_2/final.pt", "train", 12, 140.0, 160.0, incomplete=True)
    made(tmp_path, "results/other/x.parquet")
    record(tmp_path, "results/other/x.parquet", "assay", 13, 100.0, 101.0)  # another run
    jobs = finished_jobs(run, tmp_path).sort_values("start")
    assert list(jobs["rule"]) == ["analysis_behaviour", "top_seed_group", "figure_fig2", "assay"]
    assert list(jobs["seconds"]) == [3.0, 25.0, 4.0, 30.0]


def finished(rows) -> pd.DataFrame:
    table = pd.DataFrame(rows, columns=["rule", "start", "end"])
    return table.assign(seconds=table["end"] - table["start"])


def test_the_total_holds_as_jobs_finish_and_the_time_left_is_the_runs_own():
    then = finished([("train", 0, 100), ("train", 0, 100)])  # two cores busy: parallelism 2
    planned = Counter({"train": 2, "assay": 4})
    first = progress(then, planned, Counter(then["rule"]))
    assert (first.done, first.total, first.untimed) == (2, 8, 4)
    assert first.seconds_left == pytest.approx(2 * 100 / 2)  # the assays have no time yet: a lower bound
    assert first.line().startswith("pipeline: 2 of 8 jobs done (25%); at least 1m40s left (4 jobs")
    now = finished([("train", 0, 100), ("train", 0, 100), ("train", 100, 200), ("assay", 100, 110)])
    later = progress(now, planned, Counter(then["rule"]))  # the dry run's count, minus what finished since
    assert (later.done, later.total, later.untimed) == (4, 8, 0)
    parallel = (100 + 100 + 100 + 10) / 200
    assert later.seconds_left == pytest.approx((1 * 100 + 3 * 10) / parallel)
    assert "about 1m24s left at this run's job times" in later.line()
    assert Progress(8, 8, 0.0, 0).line() == "pipeline: 8 of 8 jobs done (100%)"
    assert "not known until a job has finished" in progress(finished([]), planned, Counter()).line()


def test_only_a_shipped_scale_in_the_workflows_results_has_a_line(tmp_path):
    work = scratch_workflow(tmp_path / "work")
    assert isinstance(pipeline_watch(Run("smoke", results_root=work / "results"), work), PipelineWatch)
    assert pipeline_watch(Run("smoke", results_root=tmp_path / "elsewhere"), work) is None
    assert pipeline_watch(Run("smoke-1a2b3c4d", results_root=work / "results"), work) is None  # overrides
    assert pipeline_watch(Run("smoke", results_root=tmp_path / "results"), tmp_path) is None  # no Snakefile


@pytest.mark.slow
def test_the_total_before_selection_is_the_jobs_the_run_ran(smoke_run, tmp_path, monkeypatch):
    """A dry run of a fresh copy counts, before the checkpoint has run, every job the smoke run then ran."""
    fresh = scratch_workflow(tmp_path / "fresh")
    monkeypatch.setenv("EFISH_CONFIG_DIR", str(fresh / "config"))
    planned = jobs_to_run("smoke", fresh)
    ran = finished_jobs(Run("smoke", results_root=smoke_run / "results", figures_root=smoke_run / "figures"),
                        smoke_run)
    assert planned == Counter(ran["rule"]) and "top_seed_group" in planned
    # only a dry run may plan so: a real run given planned_ranking stops in one line before any job
    result = subprocess.run(["snakemake", "--cores", "1", "--config", "scale=smoke", "planned_ranking=true"],
                            cwd=fresh, capture_output=True, text=True, timeout=600, env=smoke_env(fresh))
    assert result.returncode != 0, result.stdout[-2000:]
    assert "planned_ranking=true only counts jobs: give it with --dry-run" in result.stderr
    assert not (fresh / "results" / "smoke" / "train").exists()
    assert jobs_to_run("smoke", smoke_run) == Counter()  # all done: nothing left, and the line says so
    watch = PipelineWatch(Run("smoke", results_root=smoke_run / "results", figures_root=smoke_run / "figures"),
                          smoke_run)
    assert watch.line() == f"pipeline: {len(ran)} of {len(ran)} jobs done (100%)" and watch.finished
