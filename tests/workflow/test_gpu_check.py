"""workflow/gpu-check.sh, on a machine without a GPU: it parses, installs pyproject's dependencies but torch beside a
CUDA torch, and without a CUDA device stops in one line with exit status 3 (nothing was checked) before any test or
benchmark. What it does on a GPU (the gpu tests, the CPU-against-GPU table) is tests/rl/test_gpu.py's and
tests/bench/test_devices.py's to check."""

from __future__ import annotations

import os
import re
import subprocess
import sys
import tomllib

import pytest
import torch

from ..markdown import REPO

SCRIPT = REPO / "workflow" / "gpu-check.sh"


def run(*args: str) -> subprocess.CompletedProcess:
    """The script with this interpreter and no install step (nothing is pip-installed by the tests)."""
    env = {**os.environ, "PYTHON": sys.executable, "EFISH_GPU_CHECK_INSTALL": "0"}
    return subprocess.run([str(SCRIPT), *args], cwd=REPO, env=env, capture_output=True, text=True, timeout=120)


def test_the_script_is_executable_strict_bash_that_parses():
    assert os.access(SCRIPT, os.X_OK)
    assert "\nset -euo pipefail\n" in SCRIPT.read_text()
    assert subprocess.run(["bash", "-n", str(SCRIPT)], capture_output=True).returncode == 0


def test_beside_a_cuda_torch_it_installs_every_dependency_but_torch():
    project = tomllib.loads((REPO / "pyproject.toml").read_text())["project"]
    test = project["optional-dependencies"]["test"]
    wanted = [r for r in project["dependencies"] + test if not r.startswith("torch")]
    listed = run("--requirements")
    assert listed.returncode == 0 and listed.stdout.splitlines() == wanted
    assert len(wanted) == len(project["dependencies"]) - 1 + len(test)
    assert not any(re.match(r"torch\b", line) for line in listed.stdout.splitlines())


@pytest.mark.skipif(torch.cuda.is_available(), reason="this machine has a CUDA device: the script would check it")
def test_without_a_cuda_device_it_says_so_in_one_line_and_exits_3():
    result = run()
    assert result.returncode == 3, result.stdout + result.stderr
    assert result.stdout == f"gpu-check: no CUDA GPU: nothing checked (torch {torch.__version__} is a CPU build)\n"
    assert "pytest" not in result.stdout + result.stderr  # stopped before the tests
