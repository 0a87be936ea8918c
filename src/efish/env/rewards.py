"""Foraging and homing rewards (SPEC 7), per component so training can log each one."""

from __future__ import annotations

import numpy as np
from numba import njit

from ..config.schema import EnvConfig

FORAGING_PARTS = ("food", "shaping", "bitten", "bite", "collision", "effort", "total")
# Indices into the ``coef`` array of the foraging kernel.
FOOD, SHAPING, BITTEN, BITE, COLLISION, EFFORT, EFFORT_FREE, N_COEF = range(8)


def foraging_coefficients(cfg: EnvConfig) -> np.ndarray:
    """float64[N_COEF]: reward weights, penalties negated (as they enter the sum)."""
    c = np.zeros(N_COEF)
    c[FOOD], c[SHAPING] = cfg.reward_food, cfg.reward_shaping
    c[BITTEN], c[BITE] = -cfg.penalty_bitten, -cfg.penalty_bite
    c[COLLISION], c[EFFORT] = -cfg.penalty_collision, -cfg.penalty_effort
    c[EFFORT_FREE] = cfg.effort_free
    return c


@njit(cache=True)
def foraging_kernel(ate, d_prev, d_now, width, height, penalty_bitten, bit, collided, move, turn, c, out):
    """Every foraging component and their sum into ``out[7, B, N]`` (order of ``FORAGING_PARTS``).

    Shaping is (d_prev - d_now) / perimeter, perimeter 2 (W + H); it is 0 when
    either distance is undefined (no food left). The total adds the parts in
    order starting from 0, as Python's ``sum`` does, so -0.0 parts give +0.0.
    """
    for b in range(ate.shape[0]):
        perimeter = 2 * (width[b] + height[b])
        for i in range(ate.shape[1]):
            shaping = (d_prev[b, i] - d_now[b, i]) / perimeter
            parts = (c[FOOD] * ate[b, i],
                     c[SHAPING] * (shaping if np.isfinite(shaping) else 0.0),
                     c[BITTEN] * penalty_bitten[b, i],
                     c[BITE] * bit[b, i],
                     c[COLLISION] * collided[b, i],
                     c[EFFORT] * (max(0.0, abs(move[b, i]) - c[EFFORT_FREE])
                                  + max(0.0, abs(turn[b, i]) - c[EFFORT_FREE])))
            total = 0.0
            for k in range(len(parts)):
                out[k, b, i] = parts[k]
                total += parts[k]
            out[len(parts), b, i] = total


def foraging_rewards(cfg: EnvConfig, ate: np.ndarray, d_prev: np.ndarray, d_now: np.ndarray, width: np.ndarray,
                     height: np.ndarray, penalty_bitten: np.ndarray, bit: np.ndarray, collided: np.ndarray,
                     move: np.ndarray, turn: np.ndarray, coef: np.ndarray | None = None) -> dict[str, np.ndarray]:
    """Reward components, float64[B, N] each (views of one fresh array); ``total`` is their sum.

    ``coef``: :func:`foraging_coefficients` of ``cfg``, passed in to skip rebuilding it every step.
    """
    coef = foraging_coefficients(cfg) if coef is None else coef
    out = np.empty((len(FORAGING_PARTS),) + ate.shape)
    foraging_kernel(ate, d_prev, d_now, width, height, penalty_bitten, bit, collided, move, turn, coef, out)
    return dict(zip(FORAGING_PARTS, out))


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
