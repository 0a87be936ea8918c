"""Fault injection: a rerun with a changed config never reuses outputs of the old one."""

from __future__ import annotations

import pytest

from efish.config import compose
from efish.rl.train import train

from .test_kill_and_resume import TINY


@pytest.mark.parametrize("change", ["train.lr=1e-3", "physics.tolerance=0", "env.episode_steps=30",
                                    "sensors.noise.enabled=false"])
def test_training_under_a_changed_config_never_resumes_the_old_checkpoint(tmp_path, change):
    train(compose(TINY[:-1] + ["train.total_steps=40"]), tmp_path)
    with pytest.raises(ValueError, match=rf"another config \({change.split('=')[0]} differ\)"):
        train(compose(TINY[:-1] + ["train.total_steps=80", change]), tmp_path)
