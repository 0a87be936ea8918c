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


def test_a_condition_may_choose_the_arena_group_and_the_agent_count():
    """mute runs two designs in one assay: a condition that chooses a config group (``arena=patchy70``) is composed
    in full, on top of the assay's own choice (``uniform70``), and equals composing its overrides by hand."""
    from efish.rollout.assay import condition_configs

    configs = condition_configs(["assay=mute", "scale=smoke"])
    designs = {name: (cfg.env.n_agents, cfg.arena.layout, cfg.env.muted) for name, cfg in configs.items()}
    assert designs == {"intact": (2, "uniform", []), "muted": (2, "uniform", [1]),
                       "intact4": (4, "patchy", []), "muted4": (4, "patchy", [0])}
    assert len({cfg.assay.seed for cfg in configs.values()}) == 1  # paired episodes within a design
    for name, extra in conditions_of("mute"):
        by_hand = compose(["assay=mute", "scale=smoke", *extra])
        assert (configs[name].arena, configs[name].sensors) == (by_hand.arena, by_hand.sensors), name
        assert configs[name].env.n_agents == by_hand.env.n_agents and configs[name].env.muted == by_hand.env.muted


def test_the_authors_self_only_mode_keeps_the_own_wall_images():
    from efish.physics.plan import build_plan
    from efish.rollout.assay import condition_configs

    plans = {name: build_plan(cfg) for name, cfg in condition_configs(["assay=collective", "scale=smoke"]).items()}
    assert [n for n, p in plans.items() if p.on("wall_distortion")] == ["self_only_authors"]
    assert not plans["self_only_authors"].on("cons_part") and plans["self_only_authors"].on("self_part")
