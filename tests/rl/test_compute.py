"""train.precision (auto by measurement, fp32, bf16) and train.device: resolved once, recorded, resumed."""

from __future__ import annotations

import json
import time
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

import pytest
import torch

from efish.config import ConfigError, compose
from efish.rl import compute as compute_mod
from efish.rl.compute import Compute, gemm_rates, pass_sequences, resolve_compute, resolve_device
from efish.rl.train import CHECKPOINT, train

from .test_train import TINY, tiny, weights


def fake_rates(fp32: float, bf16: float, calls: list | None = None):
    def rates(shape, device, **timing):
        if calls is not None:
            calls.append(shape)
        return {"fp32": fp32, "bf16": bf16}
    return rates


@pytest.fixture(autouse=True)
def own_precision_cache(monkeypatch, tmp_path):
    """Each test times its machine anew: a timing kept by one test (faked rates) must not decide another's."""
    monkeypatch.setattr(compute_mod, "precision_cache", lambda: tmp_path / "precision")


def test_an_explicit_precision_is_taken_without_timing(monkeypatch):
    monkeypatch.setattr(compute_mod, "gemm_rates", lambda *a, **k: pytest.fail("timed although set"))
    for precision in ("fp32", "bf16"):
        c = resolve_compute(tiny(1, f"train.precision={precision}"))
        assert (c.precision, c.chosen_by, c.device, c.gemm_flops) == (precision, "config", torch.device("cpu"), {})


@pytest.mark.parametrize("fp32, bf16, chosen", [(100e9, 250e9, "bf16"), (100e9, 20e9, "fp32"), (100e9, 110e9, "fp32")])
def test_auto_takes_bf16_only_when_clearly_faster(monkeypatch, fp32, bf16, chosen):
    monkeypatch.setattr(compute_mod, "gemm_rates", fake_rates(fp32, bf16))
    cfg = tiny(1)
    c = resolve_compute(cfg)
    assert (c.precision, c.chosen_by) == (chosen, "auto")
    # the GEMM of the training shapes: one pass's sequences x width, times width x 3 width (the GRU)
    assert c.gemm_shape == (pass_sequences(cfg), 16, 48)
    assert c.record()["gemm_gflops"] == {"fp32": fp32 / 1e9, "bf16": bf16 / 1e9}


def test_auto_times_a_machine_once_and_keeps_it(monkeypatch, tmp_path):
    calls = []
    monkeypatch.setattr(compute_mod, "gemm_rates", fake_rates(100e9, 250e9, calls))
    first = resolve_compute(tiny(1))
    monkeypatch.setattr(compute_mod, "gemm_rates", fake_rates(100e9, 20e9, calls))  # load beside the next start
    again = resolve_compute(tiny(2))
    assert len(calls) == 1 and first.precision == again.precision == "bf16"  # the kept timing, not the loaded one
    kept = json.loads(Path(again.timing).read_text())
    assert Path(again.timing).parent == tmp_path / "precision" and kept["gemm_flops"] == {"fp32": 100e9, "bf16": 250e9}
    assert kept["threads"] == torch.get_num_threads() and kept["shape"] == list(again.gemm_shape)
    assert again.record()["gemm_timing"] == again.timing


def test_another_machine_or_shape_is_timed_anew(monkeypatch):
    calls = []
    monkeypatch.setattr(compute_mod, "gemm_rates", fake_rates(100e9, 250e9, calls))
    resolve_compute(tiny(1))
    resolve_compute(tiny(1, "train.hidden=32"))  # another GEMM shape
    identity = compute_mod.machine_identity
    monkeypatch.setattr(compute_mod, "machine_identity", lambda shape, device: {**identity(shape, device), "cpu": "x"})
    resolve_compute(tiny(1))
    assert [shape[1] for shape in calls] == [16, 32, 16]


def test_seeds_starting_together_wait_for_one_timing(monkeypatch):
    calls = []

    def slow_rates(shape, device, **timing):
        calls.append(shape)
        time.sleep(0.3)  # a second start arrives while the first times
        return {"fp32": 100e9, "bf16": 250e9}

    monkeypatch.setattr(compute_mod, "gemm_rates", slow_rates)
    with ThreadPoolExecutor(2) as pool:
        answers = list(pool.map(lambda _: compute_mod.machine_rates((8, 16, 48), torch.device("cpu"))[0], range(2)))
    assert len(calls) == 1 and answers[0] == answers[1]


def test_gemm_rates_times_both_precisions():
    rates = gemm_rates((8, 16, 48), torch.device("cpu"), min_seconds=1e-4, rounds=2)
    assert set(rates) == {"fp32", "bf16"} and all(v > 0 for v in rates.values())


def test_cuda_without_a_cuda_device_is_one_clear_error():
    if torch.cuda.is_available():
        pytest.skip("this machine has CUDA")
    with pytest.raises(ValueError, match=r"^train.device=cuda, but this torch .* sees no CUDA device") as err:
        resolve_device("cuda")
    assert "\n" not in str(err.value)
    with pytest.raises(ValueError, match="no CUDA device"):
        train(tiny(1, "train.device=cuda"), "unused")


@pytest.mark.parametrize("value", ["true", "false"])
def test_the_retired_bf16_flag_is_an_unknown_key(value):
    with pytest.raises(ConfigError, match=r"^unknown config key 'train.bf16'$"):
        compose([f"train.bf16={value}"])


def test_explicit_cpu_device_runs_the_same_code_to_the_same_weights(tmp_path):
    train(tiny(1), tmp_path / "default")
    df = train(tiny(1, "train.device=cpu", "train.precision=fp32"), tmp_path / "cpu")
    assert df.attrs["compute"]["device"] == "cpu"
    a, b = weights(tmp_path / "default"), weights(tmp_path / "cpu")
    for key in a:
        torch.testing.assert_close(a[key], b[key], rtol=0, atol=0)


def test_bf16_training_runs_and_is_recorded(tmp_path):
    df = train(tiny(2, "train.precision=bf16"), tmp_path)
    assert df.attrs["compute"]["precision"] == "bf16"
    assert torch.load(tmp_path / CHECKPOINT, weights_only=False)["precision"] == "bf16"
    assert df[["policy_loss", "value_loss", "entropy"]].notna().all().all()


def test_auto_resumes_in_the_checkpoints_precision(tmp_path, monkeypatch):
    monkeypatch.setattr(compute_mod, "gemm_rates", fake_rates(100e9, 20e9))
    train(tiny(1), tmp_path)  # auto measured fp32
    monkeypatch.setattr(compute_mod, "gemm_rates", fake_rates(100e9, 500e9))  # now bf16 would win
    df = train(tiny(2), tmp_path)
    assert df.attrs["compute"]["precision"] == "fp32" and df.attrs["compute"]["precision_chosen_by"] == "checkpoint"
    assert list(df["update"]) == [1, 2]
    train(tiny(3, "train.precision=fp32"), tmp_path)  # the explicit value auto chose is the same run
    with pytest.raises(ValueError, match=r"\(train.precision differ\)"):
        train(tiny(4, "train.precision=bf16"), tmp_path)


def test_a_checkpoint_from_before_precision_existed_still_resumes(tmp_path):
    train(tiny(1, "train.precision=fp32"), tmp_path)
    state = torch.load(tmp_path / CHECKPOINT, weights_only=False)
    del state["precision"]
    for key in ("precision", "bf16_speedup", "device"):
        del state["config"]["train"][key]
    state["config"]["train"]["bf16"] = False  # the retired flag such checkpoints recorded
    torch.save(state, tmp_path / CHECKPOINT)
    df = train(tiny(2), tmp_path)
    assert list(df["update"]) == [1, 2] and df.attrs["compute"]["precision"] == "fp32"


def test_ppo_update_runs_under_bf16_autocast():
    from efish.rl.mappo import Rollout, ppo_update
    from efish.rl.networks import Actor, Critic
    from efish.rl.value_norm import ValueNormalizer

    T, S, D, H = 10, 4, 6, 8
    g = torch.Generator().manual_seed(0)
    ro = Rollout(obs=torch.randn(T, S, D, generator=g), state=torch.randn(T, S, 2 * D, generator=g),
                 actions=torch.rand(T, S, 4, generator=g).round(), logp=-torch.rand(T, S, generator=g),
                 values=torch.zeros(T, S), advantages=torch.randn(T, S, generator=g),
                 returns=torch.randn(T, S, generator=g), starts=torch.zeros(T, S),
                 h_actor=torch.zeros(2, S, H), h_critic=torch.zeros(2, S, H))
    cfg = compose(["train.chunk=5", "train.rollout_steps=10", "train.epochs=1", "train.hidden=8"]).train
    actor, critic = Actor(D, H), Critic(2 * D, H)
    before = actor.head.weight.detach().clone()
    stats = ppo_update(cfg, actor, critic, torch.optim.Adam(actor.parameters()), torch.optim.Adam(critic.parameters()),
                       ValueNormalizer(), ro, torch.Generator().manual_seed(1), Compute(torch.device("cpu"), "bf16"))
    assert all(torch.isfinite(torch.tensor(v)) for v in stats.values())
    assert actor.head.weight.dtype == torch.float32 and not torch.equal(before, actor.head.weight)


def test_efish_train_records_the_precision_in_its_provenance(tmp_path, capsys):
    from efish.cli import main

    assert main(["train", *TINY, "train.total_steps=40", "--out", str(tmp_path)]) == 0
    record = json.loads((tmp_path / "provenance.json").read_text())["compute"]
    assert record["device"] == "cpu" and record["precision"] in ("fp32", "bf16")
    assert record["precision_chosen_by"] == "auto" and set(record["gemm_gflops"]) == {"fp32", "bf16"}
