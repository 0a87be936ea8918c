"""Training runs end to end, resumes exactly, and rejects foreign checkpoints."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest
import torch

from efish.config import compose
from efish.rl.train import CHECKPOINT, FINAL, METRICS, STAGE_COPIES, train

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
    final, checkpoint = (torch.load(tmp_path / name, weights_only=False) for name in (FINAL, CHECKPOINT))
    assert set(checkpoint) - set(final) == {STAGE_COPIES} and final["update"] == checkpoint["update"] == 2
    assert_same(final["actor"], checkpoint["actor"])  # the checkpoint's policy, without its stage copies
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


# ------------------------------------------------------------------ training stages (train.keep_stages)
STAGES = "train.keep_stages=[0.25,0.5,1.0]"
TIMING = ["wall_s", "env_steps_per_s"]


def stage_weights(path, k):
    return torch.load(path / f"stage_{k}.pt", weights_only=False)["actor"]


def assert_same(a, b):
    for key in a:
        torch.testing.assert_close(a[key], b[key], rtol=0, atol=0)


def test_stage_updates_are_the_first_to_reach_each_fraction():
    from efish.rl.train import stage_updates

    assert stage_updates([0.25, 0.5, 0.75, 1.0], 4) == [1, 2, 3, 4]
    assert stage_updates([0.3, 0.5, 1.0], 10) == [3, 5, 10]  # 0.3 * 10 is 3.0000000000000004 in floats
    assert stage_updates([0.1, 0.26, 1.0], 4) == [1, 2, 4]
    assert stage_updates([0.2, 0.4], 1) == [1, 1]
    assert stage_updates([], 7) == []


def test_stages_are_kept_at_their_updates_and_change_nothing(tmp_path):
    from efish.rl.policy import load_policy, read_stage
    from efish.rl.train import stage_paths

    plain, staged, short = tmp_path / "plain", tmp_path / "staged", tmp_path / "short"
    a = train(tiny(4, "train.checkpoint_every=3"), plain)
    b = train(tiny(4, "train.checkpoint_every=3", STAGES), staged)  # stages at updates 1, 2, 4
    pd.testing.assert_frame_equal(a.drop(columns=TIMING), b.drop(columns=TIMING))
    pd.testing.assert_frame_equal(pd.read_parquet(plain / METRICS).drop(columns=TIMING),
                                  pd.read_parquet(staged / METRICS).drop(columns=TIMING))
    final_a, final_b = (torch.load(p / FINAL, weights_only=False) for p in (plain, staged))
    for net in ("actor", "critic"):
        assert_same(final_a[net], final_b[net])
    paths = stage_paths(staged, [0.25, 0.5, 1.0])
    assert [p.name for p in paths] == ["stage_1.pt", "stage_2.pt", "stage_3.pt"]
    records = [read_stage(p) for p in paths]
    assert [(r["k"], r["fraction"], r["update"], r["env_steps"], r["total_updates"]) for r in records] == [
        (1, 0.25, 1, 40, 4), (2, 0.5, 2, 80, 4), (3, 1.0, 4, 160, 4)]
    assert not list(plain.glob("stage_*.pt"))
    # each stage is the checkpoint of its update: its metrics end there, and stage 2 is a 2-update run's final.pt
    for p, r in zip(paths, records, strict=True):
        assert [row["update"] for row in torch.load(p, weights_only=False)["metrics"]] == list(range(1, r["update"] + 1))
    train(tiny(2), short)
    assert_same(stage_weights(staged, 2), torch.load(short / FINAL, weights_only=False)["actor"])
    assert_same(stage_weights(staged, 3), final_b["actor"])  # fraction 1.0 is the final policy
    # load_policy reads a stage file and acts as the policy of that update
    obs = np.random.default_rng(0).normal(size=(3, 2, load_policy(short).obs_dim)).astype(np.float32)
    policy, reference = load_policy(paths[1]), load_policy(short / FINAL)
    h = policy.initial_hidden(3)
    np.testing.assert_array_equal(policy.act(obs, h, np.ones(3))[1], reference.act(obs, h, np.ones(3))[1])
    with pytest.raises(ValueError, match="not a training stage"):
        read_stage(short / FINAL)


class Killed(Exception):
    pass


def kill_after(n: int):
    """A progress callback that stops training during update ``n + 1``, before its checkpoint: the last
    checkpoint is the one of update ``n`` or before (as a SIGKILL there leaves it)."""
    def progress(row, total):
        if row["update"] > n:
            raise Killed
    return progress


def test_an_interrupted_run_keeps_its_stages_and_writes_the_rest(tmp_path):
    straight, killed = tmp_path / "straight", tmp_path / "killed"
    cfg = tiny(4, "train.checkpoint_every=3", "train.keep_stages=[0.5,1.0]")  # stages at updates 2 and 4
    train(cfg, straight)
    with pytest.raises(Killed):
        train(cfg, killed, progress=kill_after(2))  # killed in update 3, checkpoint of update 2 (forced by stage 1)
    assert torch.load(killed / CHECKPOINT, weights_only=False)["update"] == 2
    first = (killed / "stage_1.pt").stat()
    assert not (killed / "stage_2.pt").exists()
    df = train(cfg, killed)
    assert list(df["update"]) == [1, 2, 3, 4]
    again = (killed / "stage_1.pt").stat()
    assert (again.st_ino, again.st_mtime_ns) == (first.st_ino, first.st_mtime_ns)  # kept, not rewritten
    for k in (1, 2):
        assert_same(stage_weights(straight, k), stage_weights(killed, k))
    assert_same(stage_weights(killed, 2), torch.load(killed / FINAL, weights_only=False)["actor"])


def test_a_missing_stage_is_written_from_the_checkpoint_of_its_update_or_is_one_clear_error(tmp_path):
    cfg = tiny(2, "train.keep_stages=[0.5,1.0]")
    train(cfg, tmp_path)
    before = stage_weights(tmp_path, 2)
    (tmp_path / "stage_2.pt").unlink()   # killed between the last checkpoint and its stage
    (tmp_path / FINAL).unlink()
    train(cfg, tmp_path)                 # a finished run rerun: no update, the stage from the checkpoint
    assert_same(stage_weights(tmp_path, 2), before)
    state = torch.load(tmp_path / CHECKPOINT, weights_only=False)
    del state[STAGE_COPIES]                    # a checkpoint without its stage copies (as written before they existed)
    torch.save(state, tmp_path / CHECKPOINT)
    (tmp_path / "stage_1.pt").unlink()   # its update is behind the checkpoint: it cannot be recreated
    with pytest.raises(ValueError, match=r"stage_1\.pt \(train\.keep_stages fraction 0\.5, update 1\).*--restart"):
        train(cfg, tmp_path)
    train(tiny(2), tmp_path, restart=True)  # --restart discards the stages too
    assert not list(tmp_path.glob("stage_*.pt"))


def test_a_rerun_after_the_workflow_removed_its_outputs_writes_the_passed_stages_again(tmp_path):
    """Snakemake removes an interrupted job's outputs (final.pt, metrics.parquet and every stage) before it
    reruns it: the checkpoint's copies bring back the stages it has passed, equal to an uninterrupted run's."""
    straight, killed = tmp_path / "straight", tmp_path / "killed"
    cfg = tiny(4, "train.checkpoint_every=1", "train.keep_stages=[0.25,0.5,1.0]")  # stages at updates 1, 2, 4
    train(cfg, straight)
    with pytest.raises(Killed):
        train(cfg, killed, progress=kill_after(3))  # checkpoint of update 3, past stages 1 and 2
    for name in ("stage_1.pt", "stage_2.pt", METRICS):
        (killed / name).unlink()
    df = train(cfg, killed)
    assert list(df["update"]) == [1, 2, 3, 4]
    for k in (1, 2, 3):
        assert_same(stage_weights(straight, k), stage_weights(killed, k))
    assert STAGE_COPIES not in torch.load(killed / FINAL, weights_only=False)  # the final policy alone
    assert sorted(torch.load(killed / CHECKPOINT, weights_only=False)[STAGE_COPIES]) == [1, 2, 3]


def test_a_checkpoint_without_stages_resumes_with_them(tmp_path):
    from efish.rl.policy import read_stage

    train(tiny(1), tmp_path)                                  # no keep_stages: result-neutral
    df = train(tiny(2, "train.keep_stages=[0.5,1.0]"), tmp_path)
    assert list(df["update"]) == [1, 2]
    assert [read_stage(tmp_path / f"stage_{k}.pt")["update"] for k in (1, 2)] == [1, 2]
    with pytest.raises(ValueError, match=r"stage_1\.pt .*from another plan.*update 2"):
        train(tiny(2, "train.keep_stages=[0.25,1.0]"), tmp_path)  # 0.25 of 2 updates is update 1, kept as 0.5


@pytest.mark.parametrize("value", ["[0]", "[1.5]", "[-0.25]", "[0.5,0.25]", "[0.5,0.5]", "[a]", "[true]"])
def test_bad_keep_stages_are_one_line_errors(value):
    from efish.config import ConfigError

    with pytest.raises(ConfigError) as info:
        compose(TINY + [f"train.keep_stages={value}"])
    assert str(info.value).startswith("train.keep_stages=") and "\n" not in str(info.value)
    assert "strictly increasing fractions in (0, 1]" in str(info.value)


def test_the_scale_sets_the_stages_and_learning_needs_them():
    """scale.keep_stages reaches train.keep_stages (every seed keeps them); scale.learning without stages is one
    line naming both keys."""
    from efish.config import ConfigError

    assert compose(["scale=smoke"]).train.keep_stages == [0.5, 1.0]
    assert compose(["scale=laptop", "scale.keep_stages=[0.5,1.0]"]).train.keep_stages == [0.5, 1.0]
    with pytest.raises(ConfigError, match=r"^scale.learning=true needs scale.keep_stages"):
        compose(["scale=laptop", "scale.learning=true"])
