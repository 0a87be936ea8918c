"""Where the networks run and in which arithmetic: ``train.device`` and ``train.precision``, resolved once per run.

``precision=auto`` measures instead of guessing: bf16 GEMMs ran at a fifth of
fp32 on the developers' Xeon (AVX-512 bf16, no AMX) and at more than twice fp32
on an AMD Zen 4, so a fixed choice is wrong on one of them. At start, the
product the update runs most often (the GRU's hidden-to-hidden GEMM of one
pass: sequences x width times width x 3 width) is timed in both, and bf16 is
taken only when it is clearly faster (``train.bf16_speedup``): near ties keep
fp32's numerics. A resumed run keeps the precision its checkpoint recorded.

Randomness stays on the CPU whatever the device (action noise, minibatch
order), so a checkpoint's generator state resumes on any device.

>>> c = Compute(torch.device("cpu"), "fp32")
>>> c.record()["precision"], c.record()["device"]
('fp32', 'cpu')
"""

from __future__ import annotations

import time
from collections.abc import Callable
from dataclasses import dataclass, field

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

    def autocast(self):
        """bf16 autocast of forward passes when the precision is bf16 (a no-op context for fp32)."""
        return torch.autocast(device_type=self.device.type, dtype=torch.bfloat16, enabled=self.precision == "bf16")

    def record(self) -> dict:
        """What provenance.json and the training log say about it."""
        return {"device": str(self.device), "precision": self.precision, "precision_chosen_by": self.chosen_by,
                "gemm_shape": list(self.gemm_shape) if self.gemm_shape else None,
                "gemm_gflops": {k: round(v / 1e9, 2) for k, v in self.gemm_flops.items()}}


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


def choose_precision(t: TrainConfig, shape: tuple[int, int, int], device: torch.device) -> Compute:
    """``precision=auto``: time the training GEMM in fp32 and bf16 and take bf16 only when it runs at least
    ``t.bf16_speedup`` times as fast."""
    rates = gemm_rates(shape, device)
    faster = rates["bf16"] >= t.bf16_speedup * rates["fp32"]
    return Compute(device, "bf16" if faster else "fp32", "auto", shape, rates)


def resolve_compute(cfg: EfishConfig, recorded_precision: str | None = None) -> Compute:
    """The run's device and precision: ``train.precision`` when set, the checkpoint's when resuming under auto,
    else measured (:func:`choose_precision`). Call after ``torch.set_num_threads``: the timing uses them."""
    t = cfg.train
    device = resolve_device(t.device)
    if t.precision != "auto":
        return Compute(device, t.precision, "config")
    if recorded_precision is not None:
        return Compute(device, recorded_precision, "checkpoint")
    return choose_precision(t, (pass_sequences(cfg), t.hidden, 3 * t.hidden), device)
