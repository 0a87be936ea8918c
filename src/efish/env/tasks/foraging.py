"""Foraging (docs/model/environment.md#rewards): pellets are worth eating, approaching them is shaped, bites and
collisions cost.

The episode ends only at the time limit. Rewards come from one numba pass over
the batch (:func:`foraging_kernel`), per component so that training logs each.
"""

from __future__ import annotations

import numpy as np

from ..._jit import njit
from ...config.schema import EnvConfig
from ..geometry import nearest_pellet
from ..state import EnvState
from .base import StepEvents, Task

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
    return dict(zip(FORAGING_PARTS, out, strict=True))


class Foraging(Task):
    """Eat pellets; the shaping follows the nearest live pellet."""

    name = "foraging"
    reward_parts = FORAGING_PARTS
    distance_key = "d_food_cm"

    def __init__(self, cfg, n_agents):
        super().__init__(cfg, n_agents)
        self.coef = foraging_coefficients(cfg.env)

    def goal_distance(self, state: EnvState, out: np.ndarray) -> None:
        nearest_pellet(state.xy, state.pellet_xy, state.alive, out)

    def rewards(self, state: EnvState, events: StepEvents, d_prev: np.ndarray) -> dict[str, np.ndarray]:
        return foraging_rewards(self.cfg.env, events.ate, d_prev, state.goal_dist, state.width, state.height,
                                events.penalty_bitten, events.bit, events.collided, events.move, events.turn,
                                self.coef)
