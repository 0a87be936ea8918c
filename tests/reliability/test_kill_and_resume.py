"""Fault injection: SIGKILL a training run at random points, resume, and end with the uninterrupted weights."""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import time

import numpy as np
import pytest
import torch

from efish.config import compose
from efish.rl.train import CHECKPOINT, FINAL, METRICS, train

TINY = ["env=homing", "arena=uniform70", "arena.width_cm=30", "arena.height_cm=30", "arena.layout=none",
        "env.episode_steps=20", "train.hidden=16", "train.num_envs=2", "train.rollout_steps=20", "train.chunk=5",
        "train.epochs=2", "train.checkpoint_every=1", "train.total_steps=1200"]  # 30 updates
KILLS = 4


def efish(*args: str) -> list[str]:
    return [sys.executable, "-m", "efish", *args]


def wait_for_new_checkpoint(path, since_ns: int, proc, timeout: float = 120.0) -> bool:
    """True once ``path`` was rewritten after ``since_ns`` while ``proc`` runs."""
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline and proc.poll() is None:
        if path.exists() and path.stat().st_mtime_ns > since_ns:
            return True
        time.sleep(0.02)
    return False


@pytest.mark.slow
def test_sigkill_at_random_points_then_resume_gives_the_uninterrupted_weights(tmp_path):
    straight, killed = tmp_path / "straight", tmp_path / "killed"
    train(compose(TINY), straight)
    rng = np.random.default_rng(2026)
    kills, runs, seen = 0, 0, 0
    while not (killed / FINAL).exists():
        runs += 1
        assert runs <= KILLS + 2, "training never finished"
        proc = subprocess.Popen(efish("train", *TINY, "--out", str(killed)), stdout=subprocess.DEVNULL,
                                stderr=subprocess.PIPE, text=True)
        if kills < KILLS and wait_for_new_checkpoint(killed / CHECKPOINT, seen, proc):
            time.sleep(rng.uniform(0.0, 0.4))  # somewhere in the next update, or inside a checkpoint write
            if proc.poll() is None:
                os.kill(proc.pid, signal.SIGKILL)
                kills += 1
        _, err = proc.communicate(timeout=300)
        assert proc.returncode in (0, -signal.SIGKILL), err
        seen = (killed / CHECKPOINT).stat().st_mtime_ns if (killed / CHECKPOINT).exists() else 0
    assert kills == KILLS
    a = torch.load(straight / FINAL, weights_only=False)
    b = torch.load(killed / FINAL, weights_only=False)
    for key in a["actor"]:
        torch.testing.assert_close(a["actor"][key], b["actor"][key], rtol=0, atol=0)
    assert b["update"] == 30
    assert not [p.name for p in killed.iterdir() if p.name.startswith(".")]  # no temporaries left behind
    assert (killed / METRICS).exists()
