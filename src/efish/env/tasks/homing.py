"""Homing (docs/methods/assays.md#assay-homing): one agent, the target, stays frozen and always emits; the others home
to it.

A step within ``homing_radius_cm`` of the target earns ``homing_reward_home``,
approaching it is shaped by the perimeter, every step costs; an arena's
episode ends when a homer has been home ``homing_success_steps`` steps in a
row. No agent bites. The target is frozen by ``env.frozen`` (config/env/homing.yaml).
"""

from __future__ import annotations

import numpy as np

from ...config.schema import ArenaConfig
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

    def place(self, state: EnvState, b: int, arena: ArenaConfig, rng: np.random.Generator) -> None:
        """Target and homers uniform at least ``homing_clearance_cm`` from every wall, each homer at least
        ``homing_min_distance_cm`` from the target (docs/methods/assays.md#assay-homing); fixed ``env.starts`` win; with
        both constraints 0, the base placement."""
        e = self.cfg.env
        if e.starts or not (e.homing_min_distance_cm or e.homing_clearance_cm):
            super().place(state, b, arena, rng)
            return
        clear = max(e.homing_clearance_cm, arena.wall_margin_cm)
        lo, hi = (clear, clear), (arena.width_cm - clear, arena.height_cm - clear)
        sep = 2 * self.cfg.physics.agent_radius_cm
        for _ in range(10_000):
            xy = rng.uniform(lo, hi, size=(self.n, 2))
            gaps = np.linalg.norm(xy[:, None] - xy[None], axis=-1) + np.eye(self.n) * 1e9
            if gaps[self.target][:, ~self.target].min() >= e.homing_min_distance_cm and gaps.min() >= sep:
                state.xy[b], state.heading[b] = xy, rng.uniform(-np.pi, np.pi, self.n)
                return
        raise ValueError(f"no homing start with every homer {e.homing_min_distance_cm:g} cm from the target and "
                         f"{clear:g} cm from the walls fits a {arena.width_cm:g} x {arena.height_cm:g} cm arena")

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
