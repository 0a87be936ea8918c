"""Far-field tables: a distant source read at a few points of the sensor circle, interpolated to the sensors.

The reading of a distant source is a smooth periodic function of the angle on
the sensor circle, so its values at Q evenly spaced points carry it to every
sensor by trigonometric interpolation (see :mod:`efish.physics.sense_kernel`
for the error model). These functions build, once per plan, the point angles
and interpolation matrices of every level Q in ``physics.far_field_levels``,
and their flat forms the kernels read.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from .geometry import even_angles

if TYPE_CHECKING:
    from .plan import EffectPlan


def trig_interpolation_matrix(targets: np.ndarray, q: int) -> np.ndarray:
    """Weights W (T, q) with f(targets) ~= W @ f(2 pi k / q) for trigonometric polynomials of degree (q-1)/2.

    The periodic sinc (Dirichlet kernel) for an odd number of equispaced points.
    """
    if q % 2 == 0:
        raise ValueError(f"trigonometric interpolation needs an odd number of points, got {q}")
    x = targets[:, None] - even_angles(q)[None, :]
    half = np.sin(x / 2)
    with np.errstate(divide="ignore", invalid="ignore"):
        w = np.sin(q * x / 2) / (q * half)
    return np.where(np.abs(half) < 1e-12, 1.0, w)


def far_field_tables(levels: tuple[int, ...], morm_angles: np.ndarray, amp_angles: np.ndarray) -> dict:
    """Point angles (cos, sin) and interpolation matrices of every far-field level, zero-padded to Qmax."""
    q_max = max(levels, default=1)
    tables = np.zeros((len(levels), 2, q_max))
    morm = np.zeros((len(levels), len(morm_angles), q_max))
    amp = np.zeros((len(levels), len(amp_angles), q_max))
    for i, q in enumerate(levels):
        tables[i, 0, :q], tables[i, 1, :q] = np.cos(even_angles(q)), np.sin(even_angles(q))
        morm[i, :, :q] = trig_interpolation_matrix(morm_angles, q)
        amp[i, :, :q] = trig_interpolation_matrix(amp_angles, q)
    return {"far_levels": tuple(levels), "far_tables": tables, "morm_interp": morm, "amp_interp": amp}


def level_tables(plan: EffectPlan) -> tuple[np.ndarray, np.ndarray]:
    """Lookup tables of the far-field level choice (see ``sense_kernel.interpolation_level``).

    level_lcq: log2(C Q) per level; level_e: the order (Q + 1) / 2 per level.
    """
    q = np.array(plan.far_levels, dtype=np.float64)
    return np.log2(plan.far_safety * q), (q + 1) // 2


def flat_far_tables(plan: EffectPlan) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """The far-field levels' points and interpolation matrices stacked level after level.

    Returns offsets (int64[L + 1], level l owns rows offsets[l]:offsets[l + 1]),
    points (2, sum Q) cos and sin of the point angles, and the interpolation
    matrices (sum Q, 36) and (sum Q, 24), transposed so that each point adds
    one contiguous row to every sensor of a class.
    """
    q = np.array(plan.far_levels, dtype=np.int64)
    offsets = np.concatenate([[0], np.cumsum(q)]).astype(np.int64)
    blocks = [(plan.far_tables[i, :, :n], plan.morm_interp[i, :, :n], plan.amp_interp[i, :, :n])
              for i, n in enumerate(q)]
    points = np.concatenate([b[0] for b in blocks], axis=1) if blocks else np.zeros((2, 0))
    morm = np.concatenate([b[1] for b in blocks], axis=1) if blocks else np.zeros((len(plan.morm_angles), 0))
    amp = np.concatenate([b[2] for b in blocks], axis=1) if blocks else np.zeros((len(plan.amp_angles), 0))
    return offsets, points, np.ascontiguousarray(morm.T), np.ascontiguousarray(amp.T)
