"""Foraging rewards (SPEC 7), per component so training can log each one."""

from __future__ import annotations

import numpy as np

from ..config.schema import EnvConfig


def foraging_rewards(cfg: EnvConfig, ate: np.ndarray, d_prev: np.ndarray, d_now: np.ndarray, perimeter: np.ndarray,
                     penalty_bitten: np.ndarray, bit: np.ndarray, collided: np.ndarray, move: np.ndarray,
                     turn: np.ndarray) -> dict[str, np.ndarray]:
    """Reward components, float64[B, N] each; ``total`` is their sum.

    Shaping is (d_prev - d_now) / perimeter with d the distance to the nearest
    live pellet; it is 0 when either distance is undefined (no food left).
    """
    shaping = (d_prev - d_now) / perimeter[:, None]
    parts = {
        "food": cfg.reward_food * ate,
        "shaping": cfg.reward_shaping * np.where(np.isfinite(shaping), shaping, 0.0),
        "bitten": -cfg.penalty_bitten * penalty_bitten,
        "bite": -cfg.penalty_bite * bit,
        "collision": -cfg.penalty_collision * collided,
        "effort": -cfg.penalty_effort * (np.maximum(0.0, np.abs(move) - cfg.effort_free)
                                         + np.maximum(0.0, np.abs(turn) - cfg.effort_free)),
    }
    parts["total"] = sum(parts.values())
    return parts


def homing_rewards(cfg: EnvConfig, d_prev: np.ndarray, d_now: np.ndarray, perimeter: np.ndarray,
                   is_target: np.ndarray) -> dict[str, np.ndarray]:
    """Homing reward components (SPEC 7), float64[B, N]; the target itself gets 0."""
    home = d_now <= cfg.homing_radius_cm
    homer = ~is_target[None, :]
    parts = {
        "home": cfg.homing_reward_home * home * homer,
        "shaping": cfg.homing_shaping * (d_prev - d_now) / perimeter[:, None] * homer,
        "step": -cfg.homing_step_cost * homer * np.ones_like(d_now),
    }
    parts["total"] = sum(parts.values())
    return parts
