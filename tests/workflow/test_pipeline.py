"""The Snakemake pipeline at smoke scale: every rule runs and writes what it declares."""

from __future__ import annotations

import json
import shutil
import subprocess
from pathlib import Path

import pandas as pd
import pytest

from efish.bench.accuracy import COLUMNS

REPO = Path(__file__).resolve().parents[2]


@pytest.fixture(scope="module")
def smoke_run(tmp_path_factory) -> Path:
    """Run the whole DAG at smoke scale in a scratch copy of the workflow files."""
    work = tmp_path_factory.mktemp("pipeline")
    for name in ("Snakefile", "workflow", "config"):
        src = REPO / name
        (shutil.copytree if src.is_dir() else shutil.copy)(src, work / name)
    result = subprocess.run(
        ["snakemake", "--cores", "2", "--config", "scale=smoke", "--directory", str(work),
         "--snakefile", str(work / "Snakefile")],
        capture_output=True, text=True, timeout=900, env={**__import__("os").environ, "EFISH_CONFIG_DIR": str(work / "config")})
    assert result.returncode == 0, result.stderr[-3000:]
    return work


def test_every_declared_output_exists(smoke_run):
    for rel in ("results/smoke/bench/bench_physics.json", "results/smoke/bench/bench_accuracy.parquet",
                "results/smoke/bench/bench_accuracy.png", "figures/smoke/bench/bench_accuracy.png",
                "results/smoke/bench/config.yaml", "results/smoke/bench/provenance.json"):
        assert (smoke_run / rel).is_file(), rel


def test_accuracy_table_matches_its_schema(smoke_run):
    df = pd.read_parquet(smoke_run / "results/smoke/bench/bench_accuracy.parquet")
    assert list(df.columns) == list(COLUMNS)
    assert df["is_default"].sum() == 1
    exact = df[(df.tolerance == 0) & (df.image_order == 3) & (df.dtype == "float64") & (df.softening_m == 1e-5)]
    assert (exact["max_abs_error"] == 0).all()  # the reference itself
    assert (df["us_per_agent_step"] > 0).all()


def test_physics_bench_reports_its_numbers(smoke_run):
    r = json.loads((smoke_run / "results/smoke/bench/bench_physics.json").read_text())
    assert r["fast_agent_steps_per_s"] > 0 and r["reference_agent_steps_per_s"] > 0
    assert r["max_abs_diff_normalised"] <= 1e-6


def test_scale_is_recorded_in_the_resolved_config(smoke_run):
    assert "name: smoke" in (smoke_run / "results/smoke/bench/config.yaml").read_text()


def test_unknown_scale_fails_before_any_job(tmp_path):
    result = subprocess.run(["snakemake", "-n", "--cores", "1", "--config", "scale=huge", "--snakefile",
                             str(REPO / "Snakefile"), "--directory", str(tmp_path)], capture_output=True, text=True)
    assert result.returncode != 0
    assert "unknown scale 'huge'" in result.stdout + result.stderr


def test_workflow_lints_clean():
    result = subprocess.run(["snakemake", "--lint", "--snakefile", str(REPO / "Snakefile")], capture_output=True,
                            text=True, cwd=REPO)
    assert "Congratulations, your workflow is in a good condition" in result.stdout + result.stderr


def test_report_renders_after_a_smoke_run(smoke_run):
    result = subprocess.run(["snakemake", "--cores", "1", "--config", "scale=smoke", "--report", "report.html",
                             "--directory", str(smoke_run), "--snakefile", str(smoke_run / "Snakefile")],
                            capture_output=True, text=True, timeout=300)
    assert result.returncode == 0, result.stderr[-2000:]
    assert (smoke_run / "report.html").stat().st_size > 10_000
