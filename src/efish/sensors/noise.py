"""Seeded multiplicative sensor noise (docs/model/sensors.md#noise)."""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from ..physics.plan import EffectPlan
from ..physics.readings import RawReadings


def noise_uniforms(raw: RawReadings, rng: np.random.Generator | Sequence[np.random.Generator | None],
                   out: np.ndarray | None = None) -> np.ndarray:
    """U(0, 1) draws of one step of noise, float64, flat: Mormyromast | Ampullary | interference | Knollenorgan.

    One ``rng.random`` call for the whole batch (each block in C order). The
    noise factor is ``low + (high - low) * u``, which is what
    ``Generator.uniform(low, high)`` computes from the same draws, so this fixes
    the draw order for every consumer (``apply_noise`` and the fused encoder).

    A sequence of K generators splits the batch's arenas into K equal members
    (:class:`~efish.env.vec_env.VecEnv`): member k's arenas get the draws of
    one call of the k-th generator, in the order that call would give a batch
    of member k's arenas alone. A member whose generator is None draws nothing
    (its share of ``out`` is left as it was).
    """
    blocks = (raw.mormyromast, raw.ampullary, raw.ampullary, raw.knollenorgan)
    count = sum(block.size for block in blocks)
    if out is None or out.size != count:
        out = np.empty(count)
    rngs = [rng] if isinstance(rng, np.random.Generator) else list(rng)
    if len(rngs) == 1 and rngs[0] is not None:
        return rngs[0].random(out=out)
    # each block of ``out`` as [K members, member's share]; a member's one draw fills its share of every block
    views, start = [], 0
    for block in blocks:
        views.append(out[start: start + block.size].reshape(len(rngs), -1))
        start += block.size
    for k, member in enumerate(rngs):
        if member is None:
            continue
        draws = member.random(sum(view.shape[1] for view in views))
        for view, part in zip(views, np.split(draws, np.cumsum([v.shape[1] for v in views])[:-1]), strict=True):
            view[k] = part
    return out


def apply_noise(raw: RawReadings, emitting: np.ndarray, plan: EffectPlan, rng: np.random.Generator) -> RawReadings:
    """Multiply every raw reading by U(low, high); Ampullary readings by the interference
    range instead on steps where any conspecific of the reading agent emits.

    ``emitting``: bool[B, N]. Draws come from :func:`noise_uniforms`, so one
    generator state gives the same noise here and in the fused encoder.
    """
    (lo, hi), (jlo, jhi) = plan.noise_range, plan.interference_range
    dtype = raw.mormyromast.dtype
    u = noise_uniforms(raw, rng)
    ends = np.cumsum([raw.mormyromast.size, raw.ampullary.size, raw.ampullary.size])
    u_m, u_a, u_jam, u_k = np.split(u, ends)

    def factor(draws, low, high, shape):
        return (low + (high - low) * draws).reshape(shape).astype(dtype)

    m = raw.mormyromast * factor(u_m, lo, hi, raw.mormyromast.shape)
    plain = factor(u_a, lo, hi, raw.ampullary.shape)
    jam = factor(u_jam, jlo, jhi, raw.ampullary.shape)
    others_emit = (emitting.sum(axis=1, keepdims=True) - emitting) > 0      # [B, N]
    a = raw.ampullary * np.where(others_emit[..., None], jam, plain)
    k = raw.knollenorgan * factor(u_k, lo, hi, raw.knollenorgan.shape)
    return RawReadings(mormyromast=m, ampullary=a, knollenorgan=k)
