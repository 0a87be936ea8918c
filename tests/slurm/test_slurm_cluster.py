"""The slurm profile on a real scheduler: a one-node SLURM (workflow/slurm/local-cluster.sh) runs the smoke DAG.

The SLURM run goes through ``workflow/profiles/slurm-local``, which is the slurm
profile with each request cut to what one node has, and builds every table of
the smoke DAG plus one figure and one clip. Every job must run as a SLURM job
(its sbatch id, and sacct's COMPLETED), its tables must equal the local run's
(``table_digest`` per Parquet table, timing columns left out), and a
training job cancelled with scancel mid-run must resume from its checkpoint
when the workflow runs again. Skipped, with the reason, where the daemons,
the executor plugin or root are missing.
"""

from __future__ import annotations

import importlib.util
import os
import re
import shutil
import subprocess
import time
from pathlib import Path

import pandas as pd
import pytest

from efish.layout import Run

from ..helpers import scratch_workflow, smoke_env, table_digest

REPO = Path(__file__).resolve().parents[2]
SCRIPT = REPO / "workflow/slurm/local-cluster.sh"
NEEDED = ("slurmctld", "slurmd", "slurmdbd", "munged", "mariadbd", "sbatch", "squeue", "sacct", "scancel")
# Columns that measure the machine, not the result: they differ between any two runs.
TIMING_COLUMNS = frozenset({"wall_s", "env_steps_per_s", "us_per_agent_step", "agent_steps_per_s",
                            "fast_agent_steps_per_s", "exact_agent_steps_per_s", "fast_us_per_agent_step",
                            "exact_us_per_agent_step", "speedup"})
SUBMITTED = re.compile(r"Job \d+ has been submitted with SLURM jobid (\d+)")


def why_not() -> str | None:
    """Why this machine cannot run the one-node cluster (one line), or None."""
    missing = [c for c in NEEDED if shutil.which(c) is None]
    if missing:
        return (f"SLURM is not installed ({', '.join(missing)} missing): apt-get install slurm-wlm munge slurmdbd "
                "mariadb-server")
    if importlib.util.find_spec("snakemake_executor_plugin_slurm") is None:
        return "snakemake-executor-plugin-slurm is not installed: pip install -e '.[slurm]'"
    if os.geteuid() != 0:
        return "the one-node cluster needs root (its daemons run as root)"
    return None


needs_cluster = pytest.mark.skipif(why_not() is not None, reason=why_not() or "")


def test_the_cluster_script_says_how_to_install_what_is_missing():
    result = subprocess.run(["/bin/bash", str(SCRIPT), "up"], capture_output=True, text=True, timeout=60,
                            env={"PATH": "/nonexistent"})
    assert result.returncode != 0
    assert result.stderr.strip().splitlines() == [result.stderr.strip()]  # one line
    assert re.search(r"missing .*slurmctld.*slurmd.*: install them with apt-get install slurm-wlm munge",
                     result.stderr), result.stderr


def snakemake(work: Path, profile: str, *args: str) -> list[str]:
    """The command running the workflow copy in ``work`` (run from there: profiles read paths relative to it)."""
    return ["snakemake", "--profile", f"workflow/profiles/{profile}", "--directory", str(work),
            "--snakefile", str(work / "Snakefile"), *args]


def table_hashes(results: Path) -> dict[str, str]:
    """Relative path -> digest of every Parquet table's values (``table_digest``; timing columns left out)."""
    return {str(path.relative_to(results)): table_digest(pd.read_parquet(path), ignore=TIMING_COLUMNS)
            for path in sorted(results.glob("**/*.parquet"))}


def sacct_states(job_ids: list[str]) -> dict[str, tuple[str, str]]:
    """SLURM job id -> (state, comment) from the accounting database."""
    out = subprocess.run(["sacct", "-X", "-n", "-P", "-j", ",".join(job_ids), "--format=JobID,State,Comment"],
                         capture_output=True, text=True, timeout=60, check=True).stdout
    return {i: (s, c) for i, s, c in (line.split("|", 2) for line in out.splitlines() if line.strip())}


@pytest.fixture(scope="module")
def cluster():
    """The one-node cluster: brought up (and down afterwards) unless it already runs."""
    if why_not() is not None:
        pytest.skip(why_not())
    running = subprocess.run([str(SCRIPT), "status"], capture_output=True, timeout=60).returncode == 0
    if not running:
        up = subprocess.run([str(SCRIPT), "up"], capture_output=True, text=True, timeout=300)
        assert up.returncode == 0, up.stdout + up.stderr
    yield
    if not running:
        down = subprocess.run([str(SCRIPT), "down"], capture_output=True, text=True, timeout=300)
        assert down.returncode == 0, down.stdout + down.stderr


def slurm_targets(local: Path) -> list[str]:
    """What the SLURM run builds: every table of the local smoke run (so every job that writes one runs) and one
    job of each rule that writes none: a figure, a clip. The other figures and clips repeat those rules on other
    tables, and the contact sheet waits for every figure; leaving them to the local run keeps the SLURM run (about
    12 s a job here: each job parses the workflow again) to 61 of the DAG's 72 jobs."""
    run = Run("smoke")  # paths relative to the workflow's folder
    tables = sorted(str(p.relative_to(local)) for p in (local / run.results).glob("**/*.parquet"))
    return [*tables, str(run.bench / "bench_physics.json"), str(run.page("fig2", "png")), str(run.clip("homing"))]


@pytest.fixture(scope="module")
def smoke_runs(cluster, smoke_run, tmp_path_factory) -> dict:
    """The smoke DAG's tables through SLURM (``slurm_targets``), in its own copy of the workflow, beside the
    session's local smoke run."""
    slurm = scratch_workflow(tmp_path_factory.mktemp("slurm") / "slurm")
    targets = slurm_targets(smoke_run)
    slurm_run = subprocess.run(snakemake(slurm, "slurm-local", *targets, "--config", "scale=smoke"), cwd=slurm,
                               capture_output=True, text=True, timeout=3600, env=smoke_env(slurm))
    assert slurm_run.returncode == 0, slurm_run.stderr[-3000:]
    return {"local": smoke_run, "slurm": slurm, "log": slurm_run.stderr, "targets": targets}


@needs_cluster
@pytest.mark.slurm
@pytest.mark.slow
def test_every_job_of_the_slurm_run_ran_as_a_slurm_job(smoke_runs):
    log = smoke_runs["log"]
    steps = re.findall(r"(\d+) of (\d+) steps \(100%\) done", log)
    assert steps, log[-2000:]
    total = int(steps[-1][1])
    local = len(re.findall(r"^localrule \w+:", log, flags=re.M))  # rule all: collects outputs, runs nothing
    submitted = SUBMITTED.findall(log)
    assert len(submitted) == total - local >= 50, (total, local, len(submitted))
    states = sacct_states(submitted)
    assert set(states) == set(submitted)
    assert {state for state, _ in states.values()} == {"COMPLETED"}
    rules = {comment.split("_wildcards_")[0] for _, comment in states.values()}
    assert {"rule_train", "rule_train_policy", "rule_assay", "rule_select_seed", "rule_claims", "rule_figure_fig2",
            "rule_render_clip", "rule_bench_physics"} <= rules, rules
    assert all((smoke_runs["slurm"] / target).exists() for target in smoke_runs["targets"])
    assert not list((smoke_runs["slurm"] / "results").glob("**/*.tmp*"))


@needs_cluster
@pytest.mark.slurm
@pytest.mark.slow
def test_slurm_and_local_runs_write_the_same_tables(smoke_runs):
    local = table_hashes(smoke_runs["local"] / "results/smoke")
    slurm = table_hashes(smoke_runs["slurm"] / "results/smoke")
    assert len(local) >= 50 and sorted(slurm) == sorted(local)
    differ = sorted(k for k in local if local[k] != slurm[k])
    assert not differ, differ


@needs_cluster
@pytest.mark.slurm
@pytest.mark.slow
def test_a_training_job_cancelled_by_scancel_resumes_from_its_checkpoint(cluster, tmp_path):
    work = scratch_workflow(tmp_path / "kill")
    seed_dir = work / "results/kill/train/seed_1"
    command = snakemake(work, "slurm-local", "results/kill/train/seed_1/final.pt", "--config", "scale=smoke",
                        "overrides=scale.train_steps=12000 train.checkpoint_every=1", "run=kill")
    first = subprocess.Popen(command, cwd=work, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True,
                             env=smoke_env(work), start_new_session=True)
    try:
        deadline = time.monotonic() + 600
        while not (seed_dir / "checkpoint.pt").exists() and time.monotonic() < deadline and first.poll() is None:
            time.sleep(0.5)
        assert (seed_dir / "checkpoint.pt").exists(), "training never wrote a checkpoint"
        queued = subprocess.run(["squeue", "-h", "-o", "%i|%k"], capture_output=True, text=True, timeout=60,
                                check=True).stdout
        job = [line.split("|")[0] for line in queued.splitlines() if "|rule_train_" in line]
        assert len(job) == 1, queued
        subprocess.run(["scancel", job[0]], check=True, timeout=60)
        err = first.communicate(timeout=600)[1]
    finally:
        if first.poll() is None:
            os.killpg(first.pid, 15)
            first.wait(timeout=120)
    assert first.returncode != 0, err[-2000:]  # Snakemake saw the job fail
    assert (seed_dir / "checkpoint.pt").exists() and not (seed_dir / "final.pt").exists()
    state, _ = sacct_states(job)[job[0]]
    assert state.startswith("CANCELLED"), state

    second = subprocess.run(command, cwd=work, capture_output=True, text=True, timeout=1800, env=smoke_env(work))
    if second.returncode != 0:
        subprocess.run([*command, "--unlock"], cwd=work, capture_output=True, timeout=300, env=smoke_env(work))
    assert second.returncode == 0, second.stderr[-3000:]
    assert SUBMITTED.search(second.stderr), "the rerun did not go through SLURM"
    log = (work / "results/kill/logs/train/seed_1.log").read_text()
    resumed = re.search(r"resumed from .* at update (\d+)", log)
    assert resumed and int(resumed.group(1)) >= 1, log[-2000:]
    metrics = pd.read_parquet(seed_dir / "metrics.parquet")
    assert list(metrics["update"]) == list(range(1, 121))  # nothing lost, nothing repeated
