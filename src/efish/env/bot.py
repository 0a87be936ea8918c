"""The bounded random-walk bot (docs/methods/assays.md#assay-bot): a cue-only conspecific that ignores every input.

Each step it draws a turn U(-1, 1) and a forward drive U(0, 1) and keeps them
with probability 1 - d / R (d: distance from the arena centre, where the patch
is); otherwise it is steered back, turning towards the centre and moving only
once it faces inward. It emits with probability ``rate``, never bites, never eats.
"""

from __future__ import annotations

import numpy as np

from ..units import wrap


def bot_actions(xy: np.ndarray, heading: np.ndarray, w_max: np.ndarray, centre: np.ndarray, radius: float,
                rate: float, rng: np.random.Generator) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Mapped (move, turn, eod) for bots at ``xy`` (k, 2) with ``heading`` (k,) and turn limits ``w_max`` (k,)."""
    k = len(heading)
    turn, move, keep_draw, eod_draw = rng.uniform(-1, 1, k), rng.uniform(0, 1, k), rng.uniform(size=k), rng.uniform(size=k)
    offset = centre - xy
    d = np.linalg.norm(offset, axis=1)
    keep = keep_draw < 1.0 - d / radius if radius > 0 else np.zeros(k, bool)
    bearing = np.arctan2(offset[:, 1], offset[:, 0])
    error = wrap(bearing - heading)
    steer = np.clip(error / np.maximum(w_max, 1e-12), -1.0, 1.0)
    inward = np.cos(heading + steer * w_max - bearing) > 0
    return (np.where(keep, move, np.where(inward, move, 0.0)), np.where(keep, turn, steer), eod_draw < rate)
