"""Every assay file composes, and each of its conditions runs a few steps (VMAS checks its scenarios likewise)."""

from __future__ import annotations

import numpy as np
import pytest

from efish.config import compose, config_dir
from efish.env import VecEnv

from ..helpers import random_actions

ASSAYS = sorted(p.stem for p in (config_dir() / "assay").glob("*.yaml"))


def conditions_of(assay: str) -> list[tuple[str, list[str]]]:
    base = compose([f"assay={assay}", "scale=smoke"])
    return [(name, list(extra)) for name, extra in base.assay.conditions.items()]


@pytest.mark.parametrize("assay", ASSAYS)
def test_every_condition_of_every_assay_runs_a_few_steps(assay):
    assert compose([f"assay={assay}"]).assay.name == assay  # the file's name is the assay's name
    rng = np.random.default_rng(0)
    for name, extra in conditions_of(assay):
        cfg = compose([f"assay={assay}", "scale=smoke", *extra])
        env = VecEnv(cfg, num_envs=2, seed=cfg.assay.seed)
        obs = env.reset()
        for _ in range(3):
            obs, reward, terminated, truncated, _ = env.step(random_actions(rng, 2, env.n))
            assert np.all(np.isfinite(obs)) and np.all(np.abs(obs) <= 1), f"{assay}/{name}"
            assert np.all(np.isfinite(reward)), f"{assay}/{name}"
