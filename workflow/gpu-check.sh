#!/usr/bin/env bash
# The GPU check: what a person with a CUDA GPU runs from the root of a checkout, in under about 10 minutes:
#   workflow/gpu-check.sh
# 1. installs efish and its test extra if they are not importable, keeping a CUDA build of torch that is already
#    installed (of another version than pyproject's pin, pip would otherwise replace it with torch==2.13.0);
# 2. runs the tests marked gpu (training on the GPU matches the CPU from the same seed);
# 3. times training at the paper's width on the CPU and on the GPU (efish bench train at the paper scale, each
#    bounded by EFISH_GPU_CHECK_BENCH_S seconds, default 240) and prints them side by side, naming both.
# Exit status: 0 checked; 1 a step failed (a gpu test, a bench over its time); 3 no CUDA GPU: nothing was checked
# (one line says why: a CPU build of torch, or no device visible), so a GPU job that lost its GPU does not pass.
# EFISH_GPU_CHECK_INSTALL=0 skips step 1; PYTHON picks the interpreter (default python3);
# `workflow/gpu-check.sh --requirements` prints what step 1 installs beside a CUDA torch, and exits.
set -euo pipefail
cd "$(dirname "$0")/.."
python=${PYTHON:-python3}
bench_s=${EFISH_GPU_CHECK_BENCH_S:-240}

say() { echo "gpu-check: $*"; }
importable() { "$python" -c "import $1" 2>/dev/null; }

# pyproject's dependencies and test extra without torch: what efish needs beside a torch that is already there
requirements() {
  "$python" - <<'PY'
import re
import tomllib

with open("pyproject.toml", "rb") as f:
    project = tomllib.load(f)["project"]
for requirement in project["dependencies"] + project["optional-dependencies"]["test"]:
    if not re.match(r"torch\b", requirement):
        print(requirement)
PY
}

install() {
  if importable efish && importable pytest; then
    return
  fi
  if "$python" -c "import sys, torch; sys.exit(torch.version.cuda is None)" 2>/dev/null; then
    say "installing efish beside torch's CUDA build (--no-deps, then pyproject's other dependencies)"
    "$python" -m pip install --no-deps -e .
    requirements | "$python" -m pip install -r /dev/stdin
  else
    say "installing efish with its test extra (pip install -e \".[test]\")"
    "$python" -m pip install -e ".[test]"
  fi
}

if [ "${1:-}" = --requirements ]; then
  requirements
  exit 0
fi
if [ "${EFISH_GPU_CHECK_INSTALL:-1}" != 0 ]; then
  install
fi

if ! "$python" -c "import sys, torch; sys.exit(not torch.cuda.is_available())"; then
  why=$("$python" -c 'import torch; c = torch.version.cuda
print(f"torch {torch.__version__} " + ("is a CPU build" if c is None else f"(CUDA {c}) sees no CUDA device"))')
  say "no CUDA GPU: nothing checked ($why)"
  exit 3
fi
say "GPU: $("$python" -c "import torch; print(torch.cuda.get_device_name())"); CPU: $(
  "$python" -c "from efish.bench.timing import cpu_name; print(cpu_name())")"

say "running the tests marked gpu"
"$python" -m pytest -q -rs -p no:cacheprovider -m gpu tests/rl/test_gpu.py

width=$("$python" -c "from efish.config import compose; print(compose(['scale=paper']).train.hidden)")
threads=$(nproc)
threads=$((threads < 256 ? threads : 256))  # train.threads' upper bound
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
for device in cpu cuda; do
  say "timing training at the paper's width ($width) on $device, $threads CPU threads (at most $bench_s s)"
  status=0
  timeout "$bench_s" "$python" -m efish bench train scale=paper "train.threads=$threads" --hidden "$width" \
    --device "$device" --json > "$out/$device.json" || status=$?
  if [ "$status" -ne 0 ]; then
    say "efish bench train on $device failed or took over $bench_s s (exit $status)"
    exit 1
  fi
done
"$python" -m efish.bench.devices "$out/cpu.json" "$out/cuda.json"
