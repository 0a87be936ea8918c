"""Every command the README and the getting-started page show works after the README's own install.

The README installs with ``pip install -e .`` alone, while the rest of the suite runs in CI's environment, which
also has the ``test`` and ``docs`` extras. So a session fixture builds the environment a reader gets: a virtual
environment with only ``pip install -e .`` (pip's wheel cache makes it a download-free install; set
``EFISH_MINIMAL_VENV`` to a venv built that way to reuse one). In it, on a copy of the session's finished smoke run:

- every ``efish`` command the pages show runs as shown;
- every ``snakemake`` command at the smoke scale runs as shown (the smoke run is finished: nothing is left to do,
  except the report, which is built and must render without a docutils error);
- a ``snakemake`` command of a longer run (laptop, study, overrides) runs as a dry run, which plans every job;
- the commands a user runs on finished runs and the README names in its text (``efish compare-claims`` on two
  runs) run as well.

A command that cannot run here (an install, a SLURM cluster, a 12-minute benchmark, a web server, the test command
CI itself runs) must name where it is checked instead; a new command on either page fails
``test_every_shown_command_is_checked`` until it is given a way to be checked.
"""

from __future__ import annotations

import os
import re
import shutil
import subprocess
import sys
from dataclasses import dataclass
from pathlib import Path

import pytest

from ..helpers import smoke_env
from ..markdown import REPO, blocks, simple_commands

PAGES = ("README.md", "docs/getting-started.md")
#: A line that docutils writes for a reST problem in a report caption, e.g. ``(ERROR/3) Undefined substitution``.
DOCUTILS_PROBLEM = re.compile(r"\((WARNING/2|ERROR/3|SEVERE/4)\)")
#: Commands on finished runs that the README names in its text rather than in a code block (the second run is
#: the compare-claims tutorial's: the smoke run's claims at a stricter alpha).
ON_FINISHED_RUNS = (
    ["efish", "claims", "scale=smoke", "analysis.claims_alpha=0.01", "--results", "results/smoke", "--ranking",
     "results/smoke/analysis/selection/ranking.parquet", "--out", "results/smoke-strict/claims"],
    ["efish", "compare-claims", "smoke", "results/smoke-strict/claims"],
)


@dataclass(frozen=True)
class Check:
    """How a shown command is checked: ``argv`` to run in the minimal environment, or where it is checked instead
    (``elsewhere``), with ``nothing_to_do`` when the finished smoke run must leave Snakemake nothing to run."""

    argv: tuple[str, ...] = ()
    elsewhere: str = ""
    nothing_to_do: bool = False


def option(words: list[str], name: str) -> list[str]:
    """The values after ``name`` (up to the next ``--option``)."""
    if name not in words:
        return []
    rest = words[words.index(name) + 1:]
    end = next((i for i, w in enumerate(rest) if w.startswith("--")), len(rest))
    return rest[:end]


def check_for(words: list[str]) -> Check | None:
    """How ``words`` (one simple command of a page) is checked; None when no rule covers it."""
    program, args = words[0], words[1:]
    if program == "pip" and args[:1] == ["install"]:
        if args[1:] == ["-e", "."]:
            return Check(elsewhere="the README's install: the minimal environment is built with it")
        if m := re.fullmatch(r"\.\[([\w,]+)\]", args[-1]):
            return Check(elsewhere=f"installs the {m[1]} extra: .ci/run installs every extra the tests need")
        return Check(elsewhere="an install from another index, which these machines cannot reach")
    if program == "conda":
        return Check(elsewhere="conda is not on these machines: environment.yml pip-installs this pyproject")
    if program in ("ruff", "mkdocs") and args[:1] in (["check"], ["build"]) or words[:3] == ["python", "-m", "pytest"]:
        return Check(elsewhere="CI's own command (the README's test command) runs it with the test and docs extras")
    if words == ["mkdocs", "serve"]:
        return Check(elsewhere="a web server that runs until stopped: CI builds the same site with mkdocs build")
    if option(words, "--profile") == ["workflow/profiles/slurm-apptainer"]:
        return Check(elsewhere="needs a SLURM cluster, apptainer and the image: tests/test_container.py plans it as a "
                               "dry run")
    if program == "workflow/slurm/local-cluster.sh" or any("profiles/slurm" in w for w in option(words, "--profile")):
        return Check(elsewhere="needs a SLURM cluster and the slurm extra: tests/slurm runs it on a one-node cluster")
    if program in ("docker", "apptainer"):
        return Check(elsewhere="builds or pushes the container image, which needs a container runtime these machines "
                               "lack: tests/test_container.py checks the recipes")
    if words[:3] == ["efish", "bench", "budget"]:
        return Check(elsewhere="trains for the minutes it is given: tests/bench/test_budget_bench.py runs it at a "
                               "fraction of a minute")
    if program == "efish":
        return Check(argv=tuple(words))
    if program == "snakemake" and option(words, "--profile") == ["workflow/profiles/default"]:
        config = option(words, "--config")
        if config == ["scale=smoke"]:
            return Check(argv=tuple(words), nothing_to_do="--report" not in words)
        return Check(argv=(*words, "--dry-run"))  # a run of half an hour or more: planned, not run
    return None


def shown_commands() -> list[tuple[str, list[str]]]:
    """(where, words) of every simple command in the ``bash`` blocks of the README and getting started."""
    return [(block.where, words) for page in PAGES for block in blocks(REPO / page) if block.lang == "bash"
            for words in simple_commands(block.code)]


def runnable_commands() -> list[tuple[str, list[str]]]:
    """The shown commands that run in the minimal environment, each once, at the first place that shows it (both
    pages show some); the others are checked elsewhere (``test_every_shown_command_is_checked``)."""
    seen: set[tuple[str, ...]] = set()
    return [(where, words) for where, words in shown_commands() if (check := check_for(words)) and check.argv
            and tuple(words) not in seen and not seen.add(tuple(words))]


def test_every_shown_command_is_checked():
    found = shown_commands()
    assert len(found) >= 20 and any(w[:1] == ["efish"] for _, w in found)
    unchecked = [f"{where}: {' '.join(words)}" for where, words in found if check_for(words) is None]
    assert not unchecked, "commands with no check: give each a rule in check_for\n" + "\n".join(unchecked)


def test_the_readme_shows_the_commands_a_new_user_runs_first():
    readme = [words for where, words in shown_commands() if where.startswith("README.md")]
    for expected in (["efish", "--help"], ["efish", "plan"], ["efish", "schema", "steps"]):
        assert expected in readme, expected
    assert any("--report" in words for _, words in shown_commands())


def test_the_checks_run_what_can_run_and_name_where_the_rest_is_checked():
    assert check_for(["efish", "plan"]) == Check(argv=("efish", "plan"))
    smoke = ["snakemake", "--profile", "workflow/profiles/default", "--config", "scale=smoke"]
    assert check_for(smoke).nothing_to_do and not check_for([*smoke, "--report", "r.html"]).nothing_to_do
    assert check_for(["snakemake", "--profile", "workflow/profiles/default"]).argv[-1] == "--dry-run"
    assert "tests/slurm" in check_for(["snakemake", "--profile", "workflow/profiles/slurm"]).elsewhere
    assert "test_container" in check_for(["snakemake", "--profile", "workflow/profiles/slurm-apptainer"]).elsewhere
    assert check_for(["make", "all"]) is None


# ------------------------------------------------------------------ the minimal environment


def venv_bin(venv: Path) -> Path:
    return venv / ("Scripts" if os.name == "nt" else "bin")


@pytest.fixture(scope="session")
def minimal_venv(tmp_path_factory) -> Path:
    """A virtual environment with only the README's install (``pip install -e .``), built once per session."""
    if given := os.environ.get("EFISH_MINIMAL_VENV"):
        return Path(given)
    venv = tmp_path_factory.mktemp("minimal") / "venv"
    subprocess.run([sys.executable, "-m", "venv", str(venv)], check=True, timeout=300)
    install = subprocess.run([str(venv_bin(venv) / "pip"), "install", "-q", "-e", str(REPO)], capture_output=True,
                             text=True, timeout=1800)
    assert install.returncode == 0, install.stderr[-3000:]
    return venv


@pytest.fixture(scope="module")
def finished_run(smoke_run, tmp_path_factory) -> Path:
    """A copy of the session's smoke run (file times and Snakemake's records kept: every output is up to date)."""
    work = tmp_path_factory.mktemp("readme") / "work"
    shutil.copytree(smoke_run, work, symlinks=True)
    return work


def run_minimal(venv: Path, work: Path, argv: tuple[str, ...] | list[str]) -> subprocess.CompletedProcess:
    """``argv`` in ``work`` with the minimal environment first on PATH (and nothing of this Python's)."""
    env = {**smoke_env(work), "VIRTUAL_ENV": str(venv),
           "PATH": os.pathsep.join([str(venv_bin(venv)), os.environ.get("PATH", "")])}
    env.pop("PYTHONPATH", None)
    return subprocess.run(list(argv), cwd=work, env=env, capture_output=True, text=True, timeout=900)


@pytest.mark.slow
def test_the_minimal_environment_is_the_readme_install(minimal_venv):
    """It lacks the extras (so what it runs needs only the base install) and has the report's dependency."""
    python = str(venv_bin(minimal_venv) / "python")
    probe = ("import importlib.util as u; print(*(bool(u.find_spec(m)) for m in "
             "('efish', 'pygments', 'pytest', 'mkdocs', 'snakemake_executor_plugin_slurm')))")
    found = subprocess.run([python, "-c", probe], capture_output=True, text=True, timeout=120, check=True).stdout
    assert found.split() == ["True", "True", "False", "False", "False"], found


@pytest.mark.slow
@pytest.mark.parametrize("where, words", runnable_commands(), ids=lambda v: v if isinstance(v, str) else " ".join(v))
def test_the_shown_command_works_after_the_readme_install(where, words, minimal_venv, finished_run):
    check = check_for(words)
    result = run_minimal(minimal_venv, finished_run, check.argv)
    output = result.stdout + result.stderr
    assert result.returncode == 0, f"{where}: {' '.join(check.argv)} exited {result.returncode}\n{output[-3000:]}"
    if check.nothing_to_do:
        assert "Nothing to be done" in output, f"{where}: the finished smoke run was run again\n{output[-3000:]}"
    if "--report" in check.argv:
        report = finished_run / check.argv[check.argv.index("--report") + 1]
        assert report.stat().st_size > 10_000
        problems = [line for line in output.splitlines() if DOCUTILS_PROBLEM.search(line)]
        assert not problems, f"{where}: the report's captions have reST problems\n" + "\n".join(problems[:20])


@pytest.mark.slow
def test_commands_on_finished_runs_work_after_the_readme_install(minimal_venv, finished_run):
    for argv in ON_FINISHED_RUNS:
        result = run_minimal(minimal_venv, finished_run, argv)
        assert result.returncode == 0, f"{' '.join(argv)} exited {result.returncode}\n{result.stderr[-3000:]}"
    assert "smoke-strict verdict" in result.stdout  # the comparison names both runs
