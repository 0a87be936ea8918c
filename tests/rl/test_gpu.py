"""Training on a CUDA device computes what it computes on the CPU (marker ``gpu``; skipped, with the reason, where
torch sees no CUDA device: a matter of hardware, not of a missing package).

Both runs start from the same weights (the networks are initialised on the CPU and then moved) and draw actions
and minibatch order from the same CPU generator, so with the same seed they take the same actions and see the
same observations; only the arithmetic of the networks differs. A CUDA kernel sums in another order than the
CPU's (blocked and parallel reductions, cuDNN's fused GRU), so fp32 results agree to rounding, not bit for bit:
about 1e-7 relative per operation, grown by the two epochs of Adam steps of each update. The check allows
:data:`RTOL` (1e-3) relative and :data:`ATOL` (1e-5) absolute error on every metric of every update, far above
rounding and far below what a real difference (a wrong device transfer, a missing gradient) changes: the CPU
tests below show a 1% change of one loss fails it. TF32 (10-bit mantissa products, which cuDNN allows by default
on recent GPUs) is switched off for the comparison, so both sides compute in fp32. No GPU has run this test yet:
the tolerance is the argument above, not a measurement.
"""

from __future__ import annotations

import pandas as pd
import pytest
import torch

from efish.rl.train import train

from .test_train import tiny

RTOL, ATOL = 1e-3, 1e-5
#: Columns that time the run rather than compute it: they differ between any two runs.
TIMINGS = ("wall_s", "env_steps_per_s")
NO_CUDA = f"no CUDA device: torch.cuda.is_available() is False (torch {torch.__version__}); needs a GPU node"


def assert_same_training(expected: pd.DataFrame, actual: pd.DataFrame) -> None:
    """Every metric of every update of ``actual`` equals ``expected``'s within :data:`RTOL` and :data:`ATOL`
    (timings excluded); an AssertionError names the first column that differs."""
    assert list(actual.columns) == list(expected.columns) and len(actual) == len(expected) > 0
    for column in expected.columns.drop(list(TIMINGS)):
        torch.testing.assert_close(torch.tensor(actual[column].to_numpy(dtype=float)),
                                   torch.tensor(expected[column].to_numpy(dtype=float)), rtol=RTOL, atol=ATOL,
                                   msg=lambda m, column=column: f"{column}: {m}")


@pytest.mark.gpu
@pytest.mark.skipif(not torch.cuda.is_available(), reason=NO_CUDA)
def test_training_on_cuda_matches_the_cpu_from_the_same_seed(tmp_path, monkeypatch):
    monkeypatch.setattr(torch.backends.cuda.matmul, "allow_tf32", False)
    monkeypatch.setattr(torch.backends.cudnn, "allow_tf32", False)
    # fp32 on both: precision=auto could take bf16 on one device and fp32 on the other
    cpu = train(tiny(3, "train.precision=fp32"), tmp_path / "cpu")
    gpu = train(tiny(3, "train.precision=fp32", "train.device=cuda"), tmp_path / "cuda")
    assert cpu.attrs["compute"]["device"] == "cpu" and gpu.attrs["compute"]["device"].startswith("cuda")
    assert_same_training(cpu, gpu)


def frame(value_loss: float) -> pd.DataFrame:
    return pd.DataFrame({"update": [1, 2], "wall_s": [1.0, 2.0], "policy_loss": [-1e-3, -5e-4],
                         "value_loss": [0.5, value_loss], "approx_kl": [8e-6, 4e-6], "env_steps_per_s": [8.0, 280.0]})


def test_the_comparison_allows_rounding_and_catches_a_one_percent_change():
    assert_same_training(frame(0.4946), frame(0.4946 * (1 + 1e-5)))  # rounding-sized: equal
    assert_same_training(frame(0.4946), frame(0.4946).assign(wall_s=[9.0, 9.0]))  # timings are not compared
    assert_same_training(frame(0.4946), frame(0.4946).assign(approx_kl=[9e-6, 5e-6]))  # tiny values: ATOL
    with pytest.raises(AssertionError, match="^value_loss: "):
        assert_same_training(frame(0.4946), frame(0.4946 * 1.01))
    with pytest.raises(AssertionError):
        assert_same_training(frame(0.4946), frame(0.4946).iloc[:1])


def test_the_gpu_test_is_collected_and_skipped_with_the_reason_without_cuda(pytestconfig):
    marks = {m.name: m for m in test_training_on_cuda_matches_the_cpu_from_the_same_seed.pytestmark}
    assert "gpu" in marks and "gpu" in " ".join(pytestconfig.getini("markers"))
    skip = marks["skipif"]
    assert skip.args == (not torch.cuda.is_available(),) and "no CUDA device" in skip.kwargs["reason"]
