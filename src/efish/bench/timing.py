"""Best-of-N wall-clock timing, shared by every benchmark."""

from __future__ import annotations

import platform
import time
from pathlib import Path
from typing import TYPE_CHECKING, Callable

if TYPE_CHECKING:
    import torch


def cpu_name() -> str:
    """The CPU's model name (Linux ``/proc/cpuinfo``, else ``platform.processor()``), for quoting beside timings."""
    try:
        for line in Path("/proc/cpuinfo").read_text().splitlines():
            if line.startswith("model name"):
                return line.split(":", 1)[1].strip()
    except OSError:
        pass
    return platform.processor() or "unknown CPU"


def cpu_capability() -> str:
    """The instruction set torch's CPU kernels use here (``AVX2``, ``AVX512``, ...): it decides, among others, whether
    bf16 matrix products run at fp32's speed or far below it."""
    import torch

    try:
        return torch.backends.cpu.get_cpu_capability()
    except AttributeError:  # a torch older than 2.0
        return "unknown"


def machine() -> dict[str, str]:
    """The CPU's model name and torch capability, the keys a benchmark's rows carry beside its numbers."""
    return {"cpu": cpu_name(), "cpu_capability": cpu_capability()}


def gpu(device: torch.device) -> dict[str, str]:
    """``{"gpu": <model name>}`` when ``device`` is a CUDA device, else nothing: a row timed on a GPU
    names it beside the CPU, and a CPU row keeps the keys it always had."""
    import torch

    return {"gpu": torch.cuda.get_device_name(device)} if device.type == "cuda" else {}


def machine_line(info: dict) -> str:
    """One line naming the machine of :func:`machine`'s ``info`` (and the GPU of :func:`gpu`, when there is one),
    printed above a benchmark's table."""
    line = f"CPU: {info.get('cpu', '?')} (torch CPU capability {info.get('cpu_capability', '?')})"
    return f"{line}; GPU: {info['gpu']}" if info.get("gpu") else line


def best_time(fn: Callable[[], object], repeats: int, warmup: bool = True) -> float:
    """Fastest of ``repeats`` calls in seconds (after one warm-up call that also compiles)."""
    if warmup:
        fn()
    best = float("inf")
    for _ in range(repeats):
        t0 = time.perf_counter()
        fn()
        best = min(best, time.perf_counter() - t0)
    return best


def best_times_interleaved(fns: list[Callable[[], object]], rounds: int, warmup: bool = True) -> list[float]:
    """Fastest call of each function in seconds, calling them in turn for ``rounds`` rounds.

    For ratios between runs (fast path vs reference): this machine's speed drifts
    from minute to minute, and interleaving exposes both to the same drift.
    """
    if warmup:
        for fn in fns:
            fn()
    best = [float("inf")] * len(fns)
    for _ in range(rounds):
        for i, fn in enumerate(fns):
            t0 = time.perf_counter()
            fn()
            best[i] = min(best[i], time.perf_counter() - t0)
    return best
