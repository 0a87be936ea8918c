"""``efish bench train``: rates are positive, MFU below one, the timed pass has the configured shape; a precision
whose GEMM is far below the fastest is not timed, and the rows say so and name the CPU."""

from __future__ import annotations

import pytest
import torch

from efish.config import compose

TINY = ["env.n_agents=2", "train.num_envs=2", "train.chunk=10", "train.rollout_steps=20"]


def test_bench_train_reports_positive_rates_and_an_mfu_below_one():
    from efish.bench.train import bench_train, forward_flops

    assert forward_flops(10, 4, 2) == 2 * 10 * 4 + 2 * 4 * 4 + 12 * 4 * 4 + 2 * 4 * 2
    rows = bench_train(compose([*TINY, "bench.train_skip_below=0"]), (8,), rollout_steps=10)
    assert [r["precision"] for r in rows] == ["fp32", "bf16"]
    for r in rows:
        assert r["update_samples_per_s"] > 0 and r["rollout_env_steps_per_s"] > 0 and 0 < r["mfu"] < 1
        assert r["note"] == "" and r["cpu_capability"] and r["cpu"] and "gpu" not in r  # train.device=cpu


def test_bench_times_the_configured_pass_shape():
    from efish.bench.train import timed_sequences

    paper = compose(["scale=paper"])  # 16 arenas x 4 agents x 16 chunks = 1024 sequences per minibatch
    assert timed_sequences(paper) == paper.train.micro_sequences == 256
    assert timed_sequences(compose(["scale=paper", "train.micro_sequences=5000"])) == 1024
    assert timed_sequences(compose(["scale=paper", "train.minibatches=8", "train.micro_sequences=5000"])) == 128


def test_a_precision_far_below_the_fastest_is_skipped_and_says_why():
    from efish.bench.train import skipped_precisions

    avx2 = {"fp32": 47e9, "bf16": 0.9e9}  # the AMD EPYC of the issue: no AVX-512, bf16 ~50x below fp32
    assert skipped_precisions(avx2, 0.25) == {"bf16": "skipped: bf16 GEMM 0.9 GFLOP/s vs fp32 47"}
    assert skipped_precisions({"fp32": 40e9, "bf16": 11e9}, 0.25) == {}  # above the fraction: timed
    assert skipped_precisions({"fp32": 40e9, "bf16": 9e9}, 0.25) == {"bf16": "skipped: bf16 GEMM 9 GFLOP/s vs fp32 40"}
    assert skipped_precisions(avx2, 0.0) == {}  # 0 times every precision
    amx = {"fp32": 10e9, "bf16": 100e9}  # a GPU or AMX: fp32 is the slow one, unless auto takes it
    assert set(skipped_precisions(amx, 0.25)) == {"fp32"} and skipped_precisions(amx, 0.25, keep="fp32") == {}


@pytest.fixture
def slow_bf16(monkeypatch):
    """bench train on a machine whose bf16 GEMM runs at a 50th of fp32 (no GEMM is actually timed)."""
    from efish.bench import train
    from efish.rl.compute import Compute

    monkeypatch.setattr(train, "gemm_flops", lambda dtype, device: 47e9 if dtype == torch.float32 else 0.9e9)
    monkeypatch.setattr(train, "choose_precision", lambda t, shape, device: Compute(
        device, "fp32", "auto", shape, {"fp32": 47e9, "bf16": 0.9e9}))
    timed = []
    real = train.update_rate
    monkeypatch.setattr(train, "update_rate", lambda *a: timed.append(a[-1].precision) or real(*a))
    return timed


def test_bench_train_skips_the_slow_precision_and_the_knob_brings_it_back(slow_bf16):
    from efish.bench.train import bench_train, format_train

    lines = []
    rows = bench_train(compose([*TINY, "bench.train_hidden=[8]"]), rollout_steps=5, progress=lines.append)
    assert slow_bf16 == ["fp32"] and [r["hidden"] for r in rows] == [8, 8]  # bench.train_hidden picks the widths
    fp32, bf16 = rows
    assert fp32["auto"] and fp32["note"] == "" and fp32["update_samples_per_s"] > 0
    assert bf16["note"] == "skipped: bf16 GEMM 0.9 GFLOP/s vs fp32 47"
    assert bf16["update_samples_per_s"] is None and bf16["end_to_end_env_steps_per_s"] is None
    assert any("torch CPU capability" in line for line in lines) and any("skipped" in line for line in lines)
    text = format_train(rows)
    assert text.splitlines()[0].startswith("CPU: ") and "torch CPU capability" in text.splitlines()[0]
    assert text.splitlines()[3].rstrip().endswith("skipped: bf16 GEMM 0.9 GFLOP/s vs fp32 47")

    slow_bf16.clear()
    bench_train(compose([*TINY, "bench.train_skip_below=0"]), (8,), rollout_steps=5)
    assert slow_bf16 == ["fp32", "bf16"]


def test_the_peak_gemm_never_tries_a_size_that_would_take_too_long(monkeypatch):
    from efish.bench import train

    sizes = []
    real = torch.randn
    monkeypatch.setattr(train.torch, "randn", lambda n, m: sizes.append(n) or real(n, m))
    assert train.gemm_flops(torch.float32, sizes=(32, 64, 4096), repeats=2, max_call_seconds=1e-9) > 0
    assert sizes == [32, 32]  # a and b of the first size; the next would predict a call over the limit
    sizes.clear()
    train.gemm_flops(torch.float32, sizes=(32, 64), repeats=2)
    assert sizes == [32, 32, 64, 64]


def test_efish_bench_train_prints_its_progress_and_the_cpu(slow_bf16, capsys):
    from efish.cli import main

    assert main(["bench", "train", *TINY, "--hidden", "8"]) == 0
    out, err = capsys.readouterr()
    assert "bench train: width 8 bf16: skipped" in err and "CPU: " in out and "skipped: bf16" in out
    assert main(["bench", "train", *TINY, "--hidden", "0"]) == 2
    assert capsys.readouterr().err.strip() == "efish: error: bench train needs at least one width, each >= 1; got [0]"


@pytest.mark.parametrize("argv, cuda_seen, device", [
    ([], False, "cpu"), (["--device", "auto"], False, "cpu"), (["--device", "auto"], True, "cuda"),
    (["--device", "cuda"], False, "cuda"), (["--device", "cpu"], True, "cpu"),
])
def test_the_device_flag_sets_train_device_auto_taking_a_gpu_where_torch_sees_one(monkeypatch, argv, cuda_seen, device):
    from efish import cli
    from efish.bench import train

    seen = []
    monkeypatch.setattr(torch.cuda, "is_available", lambda: cuda_seen)
    monkeypatch.setattr(train, "bench_train", lambda cfg, progress: seen.append(cfg.train.device) or [])
    monkeypatch.setattr(train, "format_train", lambda rows: "")
    assert cli.main(["bench", "train", *TINY, *argv]) == 0 and seen == [device]



def test_a_device_other_than_auto_cpu_or_cuda_is_one_line():
    from efish.rl.compute import pick_device

    with pytest.raises(ValueError, match=r"^device must be auto, cpu or cuda, not 'tpu'$"):
        pick_device("tpu")


@pytest.mark.skipif(torch.cuda.is_available(), reason="this machine has a CUDA device")
def test_bench_on_cuda_without_a_cuda_device_is_one_line(capsys):
    from efish import cli

    assert cli.main(["bench", "train", *TINY, "--device", "cuda"]) == 2
    err = capsys.readouterr().err.strip()
    assert err.startswith("efish: error: train.device=cuda, but this torch") and "no CUDA device" in err
    assert "\n" not in err


def test_a_gpu_row_names_the_gpu_and_a_cpu_row_has_no_gpu_key():
    from efish.bench.timing import gpu, machine_line

    assert gpu(torch.device("cpu")) == {}
    cpu = {"cpu": "AMD EPYC", "cpu_capability": "AVX2"}
    assert machine_line(cpu) == "CPU: AMD EPYC (torch CPU capability AVX2)"
    assert machine_line({**cpu, "gpu": "NVIDIA H100"}) == "CPU: AMD EPYC (torch CPU capability AVX2); GPU: NVIDIA H100"
