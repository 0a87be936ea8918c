"""Seeded multiplicative sensor noise (SPEC 3.4)."""

from __future__ import annotations

import numpy as np

from ..physics.plan import EffectPlan
from ..physics.reference import RawReadings


def apply_noise(raw: RawReadings, emitting: np.ndarray, plan: EffectPlan, rng: np.random.Generator) -> RawReadings:
    """Multiply every raw reading by U(low, high); Ampullary readings by the interference
    range instead on steps where any conspecific of the reading agent emits.

    ``emitting``: bool[B, N]. Draw order is fixed (Mormyromast, Ampullary,
    interference, Knollenorgan), so one generator state gives the same noise.
    """
    lo, hi = plan.noise_range
    dtype = raw.mormyromast.dtype
    m = raw.mormyromast * rng.uniform(lo, hi, raw.mormyromast.shape).astype(dtype)
    plain = rng.uniform(lo, hi, raw.ampullary.shape)
    jam = rng.uniform(*plan.interference_range, raw.ampullary.shape)
    others_emit = (emitting.sum(axis=1, keepdims=True) - emitting) > 0      # [B, N]
    a = raw.ampullary * np.where(others_emit[..., None], jam, plain).astype(dtype)
    k = raw.knollenorgan * rng.uniform(lo, hi, raw.knollenorgan.shape).astype(dtype)
    return RawReadings(mormyromast=m, ampullary=a, knollenorgan=k)
