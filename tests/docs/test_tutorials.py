"""Every command the tutorials show runs, in order, on a finished smoke run; the README's two commands are checked.

A tutorial page (``docs/tutorials/*.md``) is a list of fenced code blocks:

- a block with a ``title`` attribute (```` ```yaml title="config/assay/dark_patchy.yaml" ````) is a file: the test
  writes it to that path (relative to the repository root, the reader's working directory);
- a ``bash`` block is run with ``bash`` under ``set -euo pipefail``, a ``python`` block with this Python, each in a
  fresh process (a shell variable does not outlive its block);
- a ``text`` or ``console`` block is output shown to the reader and is not run.

Any other block would be a step no test takes, so the extraction test refuses it. The pages are run in a copy of the
session's smoke run (``smoke_run``: the whole DAG at smoke scale; copied with its file times and Snakemake's records,
so Snakemake sees every output up to date and runs only what a page asks for). A page that edits the package
(a titled block under ``src/``, or a shell block that touches ``src/efish/``) gets its own copy of ``src/``,
``tests/`` and ``pyproject.toml``, with that ``src/`` first on ``PYTHONPATH``, so the repository is never changed.
A failing block fails its page's test with the block, its place in the page and the end of its output.
"""

from __future__ import annotations

import os
import re
import shlex
import shutil
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

from ..helpers import scratch_workflow, smoke_env
from ..markdown import FENCE_LINE, Block, blocks, commands

REPO = Path(__file__).resolve().parents[2]
TUTORIALS = REPO / "docs" / "tutorials"
PAGES = sorted(TUTORIALS.glob("*.md"))
BLOCK_TIMEOUT_S = 900
def edits_source(page_blocks: list[Block]) -> bool:
    """Whether a page writes into the package (``src/``): then it runs on its own copy of the sources."""
    return any((b.title or "").startswith("src/") or (b.lang == "bash" and "src/efish/" in b.code)
               for b in page_blocks)


#: What a page that edits the package gets a copy of: the sources, their tests and the project's pytest settings.
SOURCE_TREE = ("src", "tests", "pyproject.toml")


def tutorial_env(work: Path, page_blocks: list[Block]) -> dict:
    """The environment a page runs in: the smoke run's (``EFISH_CONFIG_DIR`` = the copy's config), and for a page
    that edits the package, a copy of the source tree with the copy's ``src/`` ahead of the installed one."""
    env = smoke_env(work)
    if edits_source(page_blocks):
        for name in SOURCE_TREE:
            src = REPO / name
            if src.is_dir():
                shutil.copytree(src, work / name, dirs_exist_ok=True,
                                ignore=shutil.ignore_patterns("__pycache__", "*.egg-info", ".pytest_cache"))
            else:
                shutil.copy2(src, work / name)
        env["PYTHONPATH"] = os.pathsep.join(p for p in (str(work / "src"), env.get("PYTHONPATH", "")) if p)
    return env


def run_block(block: Block, work: Path, env: dict, timeout: float = BLOCK_TIMEOUT_S) -> float:
    """Write (titled) or run (bash, python) ``block`` in ``work``; seconds taken. A failure fails the test with the
    block and the end of its output."""
    start = time.monotonic()
    if block.kind == "write":
        path = (work / block.title).resolve()
        assert path.is_relative_to(work.resolve()), f"{block.where}: title {block.title!r} leaves the repository"
        path.parent.mkdir(parents=True, exist_ok=True)
        path.write_text(block.code)
        return time.monotonic() - start
    if block.kind != "run":
        return 0.0
    argv = (["bash", "-c", "set -euo pipefail\n" + block.code] if block.lang == "bash"
            else [sys.executable, "-c", block.code])
    # a session of its own, so that a block over its time is stopped with everything it started (snakemake's jobs)
    with subprocess.Popen(argv, cwd=work, env=env, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                          start_new_session=True) as proc:
        try:
            stdout, stderr = proc.communicate(timeout=timeout)
        except subprocess.TimeoutExpired:
            os.killpg(proc.pid, signal.SIGKILL)
            stdout, stderr = proc.communicate()
            pytest.fail(f"{block.where}: the {block.lang} block ran over {timeout:.0f} s\n--- block\n{block.code}"
                        f"--- stderr (end)\n{stderr[-4000:]}", pytrace=False)
    if proc.returncode != 0:
        pytest.fail(f"{block.where}: the {block.lang} block exited with {proc.returncode}\n--- block\n{block.code}"
                    f"--- stdout (end)\n{stdout[-2000:]}\n--- stderr (end)\n{stderr[-4000:]}", pytrace=False)
    return time.monotonic() - start


def run_page(page: Path, work: Path) -> list[tuple[Block, float]]:
    """Every block of ``page`` in order in the finished run ``work``: (block, seconds) of each."""
    page_blocks = blocks(page)
    env = tutorial_env(work, page_blocks)
    return [(block, run_block(block, work, env)) for block in page_blocks]


# ------------------------------------------------------------------ the pages' blocks


def test_the_tutorials_exist():
    assert {p.name for p in PAGES} >= {"index.md", "add-an-assay.md", "add-an-analysis.md", "add-a-panel.md",
                                       "override-configs.md", "read-the-tables.md", "render-an-episode.md",
                                       "compare-claims.md", "watch-a-run.md",
                                       "sweep-a-parameter.md"}


@pytest.mark.parametrize("page", PAGES, ids=lambda p: p.stem)
def test_every_block_is_run_written_or_shown(page):
    """Every page has a command to run; every block is a command, a file (with a path in the repository) or output;
    every fence is closed; every Snakemake call runs at the smoke scale."""
    found = blocks(page)
    assert len(FENCE_LINE.findall(page.read_text())) == 2 * len(found), f"{page.name}: an unclosed code fence"
    assert any(b.kind == "run" for b in found), f"{page.name}: no bash or python block to run"
    for b in found:
        assert b.kind != "unknown", (f"{b.where}: a {b.lang or 'plain'} block is neither run (bash, python), written "
                                     f"(title=\"path\") nor output (text, console)")
        if b.kind == "write":
            assert b.title.strip() and not Path(b.title).is_absolute() and ".." not in Path(b.title).parts, \
                f"{b.where}: title {b.title!r} is not a path inside the repository"
        if b.lang == "bash":
            for command in commands(b.code):
                if re.search(r"(^|[;&|(]\s*)snakemake\s", command):
                    assert "scale=smoke" in command and "--cores" in command, \
                        f"{b.where}: {command!r} must run with --cores and --config scale=smoke"


def test_blocks_are_extracted_as_the_contract_says(tmp_path):
    """A titled block is a file, bash and python are run in order, text is not; a failing block fails."""
    page = tmp_path / "page.md"
    page.write_text('Intro\n\n```yaml title="config/x.yaml"\na: 1\n```\n\n!!! note\n    ```bash\n    cat config/x.yaml'
                    ' > out.txt\n    ```\n\n```python\nfrom pathlib import Path\nassert Path("out.txt").read_text()'
                    ' == "a: 1\\n"\n```\n\n```text\nnot run\n```\n')
    found = blocks(page)
    assert [b.kind for b in found] == ["write", "run", "run", "shown"]
    assert found[0].title == "config/x.yaml" and found[1].code == "cat config/x.yaml > out.txt\n"
    work = tmp_path / "work"
    work.mkdir()
    run_page(page, work)
    assert (work / "out.txt").read_text() == "a: 1\n"
    page.write_text("```bash\nfalse\n```\n")
    with pytest.raises(pytest.fail.Exception, match="exited with 1"):
        run_page(page, work)


@pytest.mark.slow
@pytest.mark.parametrize("page", PAGES, ids=lambda p: p.stem)
def test_the_tutorial_runs_on_a_smoke_run(page, smoke_run, tmp_path):
    """The page's blocks, in order, in a copy of the finished smoke run (file times kept: only what the page asks
    for runs)."""
    work = tmp_path / "work"
    shutil.copytree(smoke_run, work, symlinks=True)
    timings = run_page(page, work)
    print("\n".join(f"{b.where} {b.kind} {b.lang}: {s:.1f} s" for b, s in timings if b.kind != "shown"))


# ------------------------------------------------------------------ the README's two commands


def readme_commands() -> list[str]:
    """The README's first two ``bash`` blocks: install and run the pipeline; install, lint and test."""
    found = [b for b in blocks(REPO / "README.md") if b.lang == "bash"]
    assert len(found) >= 2, "the README opens with two bash blocks: the pipeline and the tests"
    return [b.code.strip() for b in found[:2]]


def ci_command() -> str:
    """The last command of ``.ci/run``, its variables replaced by their first plain assignment in the script."""
    lines = [line.strip() for line in (REPO / ".ci/run").read_text().splitlines()]
    lines = [line for line in lines if line and not line.startswith("#")]
    assigned = {}
    for line in lines:
        if m := re.fullmatch(r"(\w+)=(\S+)", line):
            assigned.setdefault(m[1], m[2].strip("\"'"))
    return re.sub(r"\$\{?(\w+)\}?", lambda m: assigned.get(m[1], m[0]), lines[-1])


def test_the_readme_test_command_is_what_ci_runs():
    assert readme_commands()[1] == ci_command()


@pytest.mark.slow
def test_the_readme_pipeline_command_plans_the_laptop_dag(tmp_path):
    """The README's first command, install aside, as a dry run in a scratch copy of the workflow: the whole DAG of
    the default (laptop) scale is planned."""
    install, sep, pipeline = readme_commands()[0].partition(" && ")
    assert sep and install == "pip install -e ." and pipeline.startswith("snakemake "), readme_commands()[0]
    work = scratch_workflow(tmp_path / "work")
    result = subprocess.run([*shlex.split(pipeline), "-n"], cwd=work, env=smoke_env(work), capture_output=True,
                            text=True, timeout=900)
    assert result.returncode == 0, result.stderr[-3000:]
    out = result.stdout + result.stderr
    for rule in ("train", "train_policy", "evaluate_seed", "select_seed", "bench_physics", "scene"):
        assert re.search(rf"^{rule}\s+\d+", out, re.M), f"rule {rule} is not planned:\n{out[-3000:]}"
    assert not (work / "results").exists()
