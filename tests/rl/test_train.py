"""Training runs end to end, resumes exactly, and rejects foreign checkpoints."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest
import torch

from efish.config import compose
from efish.rl.train import CHECKPOINT, METRICS, train

TINY = ["env=homing", "arena=uniform70", "arena.width_cm=30", "arena.height_cm=30", "arena.layout=none",
        "env.episode_steps=20", "train.hidden=16", "train.num_envs=2", "train.rollout_steps=20", "train.chunk=5",
        "train.epochs=2", "train.checkpoint_every=1"]


def tiny(updates: int, *extra: str):
    return compose(TINY + [f"train.total_steps={updates * 40}", *extra])


def weights(path):
    return torch.load(path / CHECKPOINT, weights_only=False)["actor"]


def test_training_writes_metrics_and_checkpoint(tmp_path):
    df = train(tiny(2), tmp_path)
    assert list(df["update"]) == [1, 2] and (tmp_path / CHECKPOINT).exists()
    stored = pd.read_parquet(tmp_path / METRICS)
    for col in ("env_steps", "wall_s", "episode_return", "reward_home", "policy_loss", "value_loss", "entropy",
                "approx_kl", "clip_fraction", "explained_variance", "env_steps_per_s"):
        assert col in stored.columns and np.isfinite(stored[col]).all(), col


def test_resumed_run_ends_with_the_same_weights(tmp_path):
    straight, resumed = tmp_path / "straight", tmp_path / "resumed"
    train(tiny(4), straight)
    train(tiny(2), resumed)                 # "killed" after 2 updates
    df = train(tiny(4), resumed)            # resumes from its checkpoint
    assert list(df["update"]) == [1, 2, 3, 4]
    a, b = weights(straight), weights(resumed)
    for key in a:
        torch.testing.assert_close(a[key], b[key], rtol=0, atol=0)


def test_truncated_checkpoint_is_one_clear_error(tmp_path):
    train(tiny(1), tmp_path)
    data = (tmp_path / CHECKPOINT).read_bytes()
    (tmp_path / CHECKPOINT).write_bytes(data[: len(data) // 2])
    with pytest.raises(ValueError, match="cannot read checkpoint"):
        train(tiny(2), tmp_path)


def test_checkpoint_of_another_architecture_is_rejected(tmp_path):
    train(tiny(1), tmp_path)
    with pytest.raises(ValueError, match="architecture"):
        train(tiny(2, "train.hidden=8"), tmp_path)
