"""Fixtures of the efish tests; the helpers they use live in ``tests/helpers.py``."""

from __future__ import annotations

import subprocess
from pathlib import Path

import pytest

from .helpers import cfg_with, scratch_workflow, smoke_env


@pytest.fixture(scope="session")
def default_cfg():
    """The composed default config (shared, do not mutate)."""
    return cfg_with()


@pytest.fixture(scope="session")
def cfg_factory():
    """``cfg_factory("a.b=1", ...)``: a cached composed config with overrides."""
    return cfg_with


@pytest.fixture(scope="session")
def smoke_run(tmp_path_factory) -> Path:
    """The whole DAG at smoke scale, run once per session in a scratch copy of the workflow files (the pipeline
    tests read it, the SLURM tests compare their run with it)."""
    work = scratch_workflow(tmp_path_factory.mktemp("pipeline"))
    result = subprocess.run(
        ["snakemake", "--cores", "2", "--config", "scale=smoke", "--directory", str(work),
         "--snakefile", str(work / "Snakefile")],
        capture_output=True, text=True, timeout=2400, env=smoke_env(work))
    assert result.returncode == 0, result.stderr[-3000:]
    return work
