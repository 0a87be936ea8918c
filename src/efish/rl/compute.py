"""Where the networks run and in which arithmetic: ``train.device`` and ``train.precision``, resolved once per run.

``precision=auto`` measures instead of guessing: bf16 GEMMs ran at a fifth of
fp32 on the developers' Xeon (AVX-512 bf16, no AMX) and at more than twice fp32
on an AMD Zen 4, so a fixed choice is wrong on one of them. The product the
update runs most often (the GRU's hidden-to-hidden GEMM of one pass: sequences
x width times width x 3 width) is timed in both, and bf16 is taken only when it
is clearly faster (``train.bf16_speedup``): near ties keep fp32's numerics.

The timing is made once per machine and kept (:func:`machine_rates`): timed
at every start, a seed started while the other core was busy read a ratio
below the threshold and trained in fp32 while its siblings trained in bf16,
so which arithmetic a seed learnt in depended on the load beside it. A resumed
run keeps the precision its checkpoint recorded.

Randomness stays on the CPU whatever the device (action noise, minibatch
order), so a checkpoint's generator state resumes on any device.

>>> c = Compute(torch.device("cpu"), "fp32")
>>> c.record()["precision"], c.record()["device"]
('fp32', 'cpu')
"""

from __future__ import annotations

import fcntl
import hashlib
import json
import os
import platform
import time
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path

import torch

from ..config.schema import EfishConfig, TrainConfig

DTYPES = {"fp32": torch.float32, "bf16": torch.bfloat16}


@dataclass(frozen=True)
class Compute:
    """The resolved device and precision of a run, with how the precision was chosen.

    ``gemm_flops``: the timed GEMM rate per precision, FLOP/s (empty when
    nothing was timed); ``chosen_by``: ``auto``, ``config`` or ``checkpoint``.
    """

    device: torch.device
    precision: str
    chosen_by: str = "config"
    gemm_shape: tuple[int, int, int] | None = None
    gemm_flops: dict[str, float] = field(default_factory=dict)
    timing: str | None = None

    def autocast(self):
        """bf16 autocast of forward passes when the precision is bf16 (a no-op context for fp32)."""
        return torch.autocast(device_type=self.device.type, dtype=torch.bfloat16, enabled=self.precision == "bf16")

    def record(self) -> dict:
        """What provenance.json and the training log say about it."""
        return {"device": str(self.device), "precision": self.precision, "precision_chosen_by": self.chosen_by,
                "gemm_shape": list(self.gemm_shape) if self.gemm_shape else None,
                "gemm_gflops": {k: round(v / 1e9, 2) for k, v in self.gemm_flops.items()},
                "gemm_timing": self.timing}


CPU_FP32 = Compute(torch.device("cpu"), "fp32")


def resolve_device(name: str) -> torch.device:
    """``train.device`` as a torch device; cuda without a CUDA device is one clear error."""
    if name == "cuda" and not torch.cuda.is_available():
        raise ValueError(f"train.device=cuda, but this torch ({torch.__version__}) sees no CUDA device: run on a GPU "
                         "node with a CUDA build of torch, or set train.device=cpu")
    return torch.device(name)


def pick_device(name: str) -> str:
    """A device choice as a ``train.device`` value: ``auto`` is cuda where torch sees a GPU, else cpu; cpu and cuda
    are kept (a cuda this machine lacks fails later, in :func:`resolve_device`, with its one-line reason)."""
    if name not in ("auto", "cpu", "cuda"):
        raise ValueError(f"device must be auto, cpu or cuda, not {name!r}")
    if name == "auto":
        return "cuda" if torch.cuda.is_available() else "cpu"
    return name


def synchronizer(device: torch.device) -> Callable[[], None]:
    """A call that waits for ``device``'s queued work: CUDA runs kernels asynchronously, so a timing that stops the
    clock before this measures the launch, not the work. A no-op on the CPU."""
    return torch.cuda.synchronize if device.type == "cuda" else (lambda: None)


def pass_sequences(cfg: EfishConfig) -> int:
    """Sequences in one forward/backward pass of the update: a minibatch of chunks (arenas x agents x
    rollout/chunk / minibatches), cut to ``train.micro_sequences``."""
    t = cfg.train
    per_minibatch = max(1, t.num_envs * cfg.env.n_agents * (t.rollout_steps // t.chunk) // t.minibatches)
    return min(per_minibatch, t.micro_sequences)


def gemm_rates(shape: tuple[int, int, int], device: torch.device, precisions=("fp32", "bf16"),
               min_seconds: float = 0.02, rounds: int = 5) -> dict[str, float]:
    """FLOP/s of an (m x k) @ (k x n) product per precision: the best of ``rounds`` rounds, the precisions timed in
    turn within each round (so both see the same machine load), each round at least ``min_seconds`` long."""
    m, k, n = shape
    gen = torch.Generator().manual_seed(0)
    pairs = {p: (torch.randn(m, k, generator=gen).to(device, DTYPES[p]),
                 torch.randn(k, n, generator=gen).to(device, DTYPES[p])) for p in precisions}
    sync = synchronizer(device)
    calls = {}
    for p, (a, b) in pairs.items():  # warm up, and find how many calls fill min_seconds
        a @ b
        sync()
        t0 = time.perf_counter()
        a @ b
        sync()
        calls[p] = max(1, int(min_seconds / max(time.perf_counter() - t0, 1e-7)))
    best = dict.fromkeys(precisions, float("inf"))
    for _ in range(rounds):
        for p, (a, b) in pairs.items():
            t0 = time.perf_counter()
            for _ in range(calls[p]):
                a @ b
            sync()
            best[p] = min(best[p], (time.perf_counter() - t0) / calls[p])
    return {p: 2.0 * m * k * n / best[p] for p in precisions}


def choose_precision(t: TrainConfig, shape: tuple[int, int, int], device: torch.device,
                     rates: dict[str, float] | None = None, timing: str | None = None) -> Compute:
    """``precision=auto``: bf16 only when its GEMM runs at least ``t.bf16_speedup`` times as fast as fp32, by
    ``rates`` (FLOP/s per precision; timed now when None). ``timing`` says where the rates come from."""
    rates = gemm_rates(shape, device) if rates is None else rates
    faster = rates["bf16"] >= t.bf16_speedup * rates["fp32"]
    return Compute(device, "bf16" if faster else "fp32", "auto", shape, rates, timing)


def precision_cache() -> Path:
    """Where the machines' GEMM timings are kept: ``$XDG_CACHE_HOME/efish/precision`` (``~/.cache`` without it),
    beside the compiled kernels (efish._numba_cache)."""
    return Path(os.environ.get("XDG_CACHE_HOME") or Path.home() / ".cache") / "efish" / "precision"


def machine_identity(shape: tuple[int, int, int], device: torch.device) -> dict:
    """What a GEMM timing is valid for: the processor (its model and instruction sets), torch's version and the
    CPU kernels it dispatches to, the threads, the device and the product's shape. Another of any is timed anew."""
    cpu = platform.processor() or platform.machine()
    flags = ""
    cpuinfo = Path("/proc/cpuinfo")
    if cpuinfo.is_file():
        lines = cpuinfo.read_text().splitlines()
        cpu = next((ln.split(":", 1)[1].strip() for ln in lines if ln.startswith("model name")), cpu)
        flags = next((ln.split(":", 1)[1].strip() for ln in lines if ln.startswith("flags")), "")
    return {"cpu": cpu, "cpu_flags": hashlib.sha256(flags.encode()).hexdigest()[:12], "torch": torch.__version__,
            "cpu_capability": torch.backends.cpu.get_cpu_capability(), "threads": torch.get_num_threads(),
            "device": torch.cuda.get_device_name(device) if device.type == "cuda" else str(device),
            "shape": list(shape)}


def machine_rates(shape: tuple[int, int, int], device: torch.device) -> tuple[dict[str, float], Path]:
    """The GEMM rates per precision of this machine (:func:`machine_identity`), timed the first time and read from
    :func:`precision_cache` after, with the file they are kept in. A file lock makes seeds that start together wait
    for one timing instead of timing against each other. Delete the file to time again."""
    identity = machine_identity(shape, device)
    key = hashlib.sha256(json.dumps(identity, sort_keys=True).encode()).hexdigest()[:16]
    folder = precision_cache()
    folder.mkdir(parents=True, exist_ok=True)
    path = folder / f"{key}.json"
    with open(folder / f"{key}.lock", "w") as lock:
        fcntl.flock(lock, fcntl.LOCK_EX)
        if path.is_file():
            return json.loads(path.read_text())["gemm_flops"], path
        rates = gemm_rates(shape, device, min_seconds=0.05, rounds=7)  # once per machine: worth a second
        record = {**identity, "gemm_flops": rates, "timed": time.strftime("%Y-%m-%dT%H:%M:%S")}
        tmp = path.with_suffix(".tmp")
        tmp.write_text(json.dumps(record, indent=1))
        tmp.replace(path)
    return rates, path


def resolve_compute(cfg: EfishConfig, recorded_precision: str | None = None) -> Compute:
    """The run's device and precision: ``train.precision`` when set, the checkpoint's when resuming under auto,
    else this machine's kept timing (:func:`machine_rates`). Call after ``torch.set_num_threads``: the timing
    uses them."""
    t = cfg.train
    device = resolve_device(t.device)
    if t.precision != "auto":
        return Compute(device, t.precision, "config")
    if recorded_precision is not None:
        return Compute(device, recorded_precision, "checkpoint")
    shape = (pass_sequences(cfg), t.hidden, 3 * t.hidden)
    rates, path = machine_rates(shape, device)
    return choose_precision(t, shape, device, rates, str(path))
