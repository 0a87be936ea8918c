"""Homing (SPEC 7, 9, 11): one agent, the target, stays frozen and always emits; the others home to it.

A step within ``homing_radius_cm`` of the target earns ``homing_reward_home``,
approaching it is shaped by the perimeter, every step costs; an arena's
episode ends when a homer has been home ``homing_success_steps`` steps in a
row. No agent bites. The target is frozen by ``env.frozen`` (config/env/homing.yaml).
"""

from __future__ import annotations

import numpy as np

from ..state import EnvState
from .base import StepEvents, Task


class Homing(Task):
    """Reach the always-emitting target and stay there."""

    name = "homing"
    reward_parts = ("home", "shaping", "step", "total")
    distance_key = "d_target_cm"

    def __init__(self, cfg, n_agents):
        super().__init__(cfg, n_agents)
        self.target = np.arange(n_agents) == cfg.env.homing_target
        self.forced_eod = self.target.copy()
        self.bite_allowed = False

    def new_state(self, num_envs: int) -> dict[str, np.ndarray]:
        return {"home_steps": np.zeros((num_envs, self.n), np.int64)}  # consecutive steps at home

    def goal_distance(self, state: EnvState, out: np.ndarray) -> None:
        out[:] = np.linalg.norm(state.xy - state.xy[:, self.target], axis=-1)

    def rewards(self, state: EnvState, events: StepEvents, d_prev: np.ndarray) -> dict[str, np.ndarray]:
        """Components [B, N] (the target gets 0); counts the consecutive steps at home."""
        e, d_now = self.cfg.env, state.goal_dist
        perimeter = 2 * (state.width + state.height)
        homer = ~self.target[None, :]
        parts = {
            "home": e.homing_reward_home * (d_now <= e.homing_radius_cm) * homer,
            "shaping": e.homing_shaping * (d_prev - d_now) / perimeter[:, None] * homer,
            "step": -e.homing_step_cost * homer * np.ones_like(d_now),
        }
        parts["total"] = sum(parts.values())
        at_home = (d_now <= e.homing_radius_cm) & ~self.target
        state.task["home_steps"] = np.where(at_home, state.task["home_steps"] + 1, 0)
        return parts

    def terminated(self, state: EnvState) -> np.ndarray:
        return (state.task["home_steps"] >= self.cfg.env.homing_success_steps).any(axis=1)
