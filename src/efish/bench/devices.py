"""Training speed on the CPU and on a GPU side by side: the table ``workflow/gpu-check.sh`` prints.

It reads two outputs of ``efish bench train --json`` of the same config and widths, one run with ``--device
cpu`` and one with ``--device cuda``, and puts each (width, precision) row's update and end-to-end rates next to
each other with the GPU's end-to-end speed-up, under the line naming the CPU and the GPU, and ends with the
comparison that matters for a training job: each device at the precision ``train.precision=auto`` takes there
(bf16 on most GPUs, fp32 on a CPU without AVX-512), where a precision far slower than the other is not timed at
all (``bench.train_skip_below``), so a row may have one device's rates only. Only the networks move to the GPU
(the env steps on the CPU either way), so the end-to-end ratio, not the update's, is what a training job gains.
Run it as ``python -m efish.bench.devices cpu.json cuda.json``.

>>> row = {"hidden": 8, "precision": "fp32", "auto": True, "update_samples_per_s": 100.0,
...        "end_to_end_env_steps_per_s": 10.0, "cpu": "X", "cpu_capability": "AVX2"}
>>> print(side_by_side([row], [{**row, "update_samples_per_s": 400.0, "end_to_end_env_steps_per_s": 25.0,
...                               "gpu": "G"}]).splitlines()[2])
     8   fp32              100              400                        10.0                        25.0     2.50x
"""

from __future__ import annotations

import argparse
import json
import sys
from collections.abc import Sequence
from pathlib import Path

from .timing import machine_line

_KEY = ("hidden", "precision")


def _cell(value: float | None, spec: str, width: int) -> str:
    return f"{'-':>{width}}" if value is None else f"{value:>{width}{spec}}"


def _auto(rows: list[dict], hidden: int) -> dict:
    """The row of width ``hidden`` at the precision ``train.precision=auto`` takes (always timed)."""
    return next(r for r in rows if r["hidden"] == hidden and r["auto"])


def side_by_side(cpu: list[dict], gpu: list[dict]) -> str:
    """The CPU's and the GPU's rows (``bench_train`` records) of the same widths and precisions as one table (a
    rate not timed, a skipped precision, shows ``-``), then per width the end-to-end rates at each device's
    ``train.precision=auto`` choice and their ratio. ValueError when the two did not time the same rows."""
    on_gpu = {tuple(r[k] for k in _KEY): r for r in gpu}
    if not cpu or sorted(on_gpu) != sorted(tuple(r[k] for k in _KEY) for r in cpu):
        raise ValueError("the CPU and GPU benchmarks did not time the same widths and precisions")
    head = (f"{'hidden':>6} {'prec':>6} {'update/s CPU':>16} {'update/s GPU':>16} {'env-steps/s end to end CPU':>27} "
            f"{'env-steps/s end to end GPU':>27} {'GPU/CPU':>9}")
    lines = [machine_line(gpu[0]), head]
    for c in cpu:
        g = on_gpu[tuple(c[k] for k in _KEY)]
        both = c["end_to_end_env_steps_per_s"], g["end_to_end_env_steps_per_s"]
        ratio = f"{both[1] / both[0]:>8.2f}x" if None not in both else f"{'-':>9}"
        lines.append(f"{c['hidden']:>6} {c['precision']:>6} "
                     f"{_cell(c['update_samples_per_s'], ',.0f', 16)} {_cell(g['update_samples_per_s'], ',.0f', 16)} "
                     f"{_cell(both[0], ',.1f', 27)} {_cell(both[1], ',.1f', 27)} {ratio}")
    lines.append("update/s: update samples/s; - not timed (bench.train_skip_below)")
    for hidden in dict.fromkeys(r["hidden"] for r in cpu):
        c, g = _auto(cpu, hidden), _auto(gpu, hidden)
        c_rate, g_rate = c["end_to_end_env_steps_per_s"], g["end_to_end_env_steps_per_s"]
        lines.append(f"width {hidden}, as train.precision=auto trains: CPU {c['precision']} {c_rate:,.1f}, GPU "
                     f"{g['precision']} {g_rate:,.1f} env-steps/s end to end: {g_rate / c_rate:.2f}x")
    return "\n".join(lines)


def main(argv: Sequence[str] | None = None) -> int:
    """Print :func:`side_by_side` of two JSON files; an unreadable file or mismatched rows is one line, exit 2."""
    parser = argparse.ArgumentParser(prog="python -m efish.bench.devices", description=__doc__.split("\n")[0])
    parser.add_argument("cpu", type=Path, help="efish bench train --device cpu --json output")
    parser.add_argument("gpu", type=Path, help="efish bench train --device cuda --json output")
    args = parser.parse_args(argv)
    try:
        print(side_by_side(*(json.loads(path.read_text()) for path in (args.cpu, args.gpu))))
    except (OSError, ValueError, KeyError, TypeError) as exc:
        reason = f"a row lacks the field {exc}" if isinstance(exc, KeyError) else str(exc)
        print(f"efish bench devices: error: {reason}", file=sys.stderr)
        return 2
    return 0


if __name__ == "__main__":
    sys.exit(main())
