"""Training runs end to end, resumes exactly, and rejects foreign checkpoints."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest
import torch

from efish.config import compose
from efish.rl.train import CHECKPOINT, FINAL, METRICS, train

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
    assert (tmp_path / FINAL).read_bytes() == (tmp_path / CHECKPOINT).read_bytes()
    stored = pd.read_parquet(tmp_path / METRICS)
    for col in ("env_steps", "wall_s", "episode_return", "reward_home", "policy_loss", "value_loss", "entropy",
                "approx_kl", "clip_fraction", "explained_variance", "env_steps_per_s"):
        assert col in stored.columns and np.isfinite(stored[col]).all(), col


@pytest.mark.slow
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
    with pytest.raises(ValueError, match="cannot read checkpoint .*--restart"):
        train(tiny(2), tmp_path)


def test_checkpoint_of_another_config_is_rejected_naming_the_keys(tmp_path):
    train(tiny(1), tmp_path)
    with pytest.raises(ValueError, match=r"another config \(train.hidden differ\).*--restart"):
        train(tiny(2, "train.hidden=8"), tmp_path)
    with pytest.raises(ValueError, match=r"\(physics.tolerance, train.lr differ\)"):
        train(tiny(2, "train.lr=1e-3", "physics.tolerance=0"), tmp_path)


def test_result_neutral_keys_still_resume(tmp_path):
    train(tiny(1), tmp_path)
    df = train(tiny(2, "train.threads=2", "train.checkpoint_every=5"), tmp_path)  # a longer run, other threads
    assert list(df["update"]) == [1, 2]


def test_a_checkpoint_past_the_run_is_rejected(tmp_path):
    train(tiny(2), tmp_path)
    with pytest.raises(ValueError, match="past this run's 1 updates"):
        train(tiny(1), tmp_path)


def test_restart_discards_the_checkpoint(tmp_path):
    train(tiny(1), tmp_path)
    df = train(tiny(1, "train.lr=1e-3"), tmp_path, restart=True)
    assert list(df["update"]) == [1]
    assert torch.load(tmp_path / CHECKPOINT, weights_only=False)["config"]["train"]["lr"] == 1e-3


def test_a_finished_run_rerun_writes_its_outputs_again(tmp_path):
    train(tiny(2), tmp_path)
    before = weights(tmp_path)
    (tmp_path / FINAL).unlink()
    (tmp_path / METRICS).unlink()  # what Snakemake does before rerunning a job
    df = train(tiny(2), tmp_path)
    assert list(df["update"]) == [1, 2] and (tmp_path / FINAL).exists()
    assert list(pd.read_parquet(tmp_path / METRICS)["update"]) == [1, 2]
    for key, value in before.items():
        torch.testing.assert_close(weights(tmp_path)[key], value, rtol=0, atol=0)


def test_loaded_policy_steps_the_env_with_hidden_states_exposed(tmp_path):
    from efish.env import VecEnv
    from efish.rl.policy import load_policy

    cfg = tiny(1)
    train(cfg, tmp_path)
    policy = load_policy(tmp_path)
    env = VecEnv(cfg, num_envs=3, seed=0)
    obs, h = env.reset(), policy.initial_hidden(3)
    starts = np.ones(3)
    for _ in range(5):
        actions, h_next = policy.act(obs, h, starts)
        assert actions.shape == (3, 2, 4) and h_next.shape == (3, 2, 16)
        assert set(np.unique(actions[..., 2:])) <= {0.0, 1.0}
        obs, _, term, trunc, _ = env.step(actions)
        h, starts = h_next, (term | trunc).astype(float)
    # the same inputs give the same deterministic actions
    np.testing.assert_array_equal(policy.act(obs, h, starts)[0], policy.act(obs, h, starts)[0])


def test_load_policy_names_a_missing_checkpoint(tmp_path):
    from efish.rl.policy import load_policy

    with pytest.raises(ValueError, match="no checkpoint"):
        load_policy(tmp_path / "nothing")


@pytest.mark.slow
def test_homing_return_rises_with_training(tmp_path):
    """40 short updates on a 24 cm homing arena: the return of the last 8 updates beats the first 8
    by more than 3 standard errors (measured over seeds 1-3: differences of 9-10 against errors of ~1.4)."""
    cfg = compose(["env=homing", "arena=uniform70", "arena.width_cm=24", "arena.height_cm=24", "arena.layout=none",
                   "env.episode_steps=50", "train.hidden=32", "train.num_envs=16", "train.rollout_steps=50",
                   "train.chunk=10", "train.total_steps=32000", "train.epochs=4", "train.lr=1e-3",
                   "train.checkpoint_every=1000", "sensors.noise.enabled=false", "train.seed=2"])
    r = train(cfg, tmp_path)["episode_return"].to_numpy()
    first, last = r[:8], r[-8:]
    stderr = np.sqrt(first.var(ddof=1) / 8 + last.var(ddof=1) / 8)
    assert last.mean() - first.mean() > 3 * stderr, (first, last)
