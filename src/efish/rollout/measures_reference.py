"""The numpy formulas of the per-step measures: the slow twin of :mod:`efish.rollout.measure_kernels`.

These were :mod:`efish.rollout.measures`' own code before its kernels; they
stay as the readable statement of what each column is, and as the oracle the
kernels are tested against (``tests/rollout/test_measure_kernels.py``). Same
arguments and outputs as the functions of :mod:`efish.rollout.measures` they
are named after. Never called by an assay: they build [B, N, N + P, 2] arrays
at every step.
"""

from __future__ import annotations

import numpy as np

from ..env.geometry import nearest_pellet
from ..env.vec_env import VecEnv
from ..physics.fields import induced_dipole, pairwise_dipole_field
from ..physics.reference import intrinsic_moments
from ..units import CM, wrap
from .measures import SECTORS, eod_field


def nearest_reference(env: VecEnv) -> dict[str, np.ndarray]:
    """:func:`efish.rollout.measures.nearest`, by sorting the [B, N, N] distances (stable: ties by index)."""
    s = env.state
    xy, h = s.xy, s.heading
    d = xy[:, None, :, :] - xy[:, :, None, :]                       # [B, N(i), N(j), 2]: j - i
    dist = np.linalg.norm(d, axis=-1) + np.where(np.eye(env.n, dtype=bool), np.inf, 0.0)
    order = np.argsort(dist, axis=-1, kind="stable")
    j = order[..., 0]
    pick = np.take_along_axis(d, j[..., None, None], axis=2)[:, :, 0]
    out = {"dist_agent_cm": dist.min(axis=-1), "bearing_agent_rad": wrap(np.arctan2(pick[..., 1], pick[..., 0]) - h)}
    sizes = np.broadcast_to(s.size[:, None, :], dist.shape)
    for rank, key in ((0, "1"), (1, "2")):
        has = env.n > rank + 1
        k = order[..., min(rank, env.n - 1)]
        out[f"size_agent{key}"] = np.take_along_axis(sizes, k[..., None], -1)[..., 0] if has else np.full(h.shape, np.nan)
    out["dist_agent2_cm"] = np.sort(dist, axis=-1)[..., 1] if env.n > 2 else np.full(h.shape, np.nan)
    if env.n == 1:
        out["dist_agent_cm"][:], out["bearing_agent_rad"][:] = np.nan, np.nan
    dist_food, k = np.empty(h.shape), np.empty(h.shape, np.int64)
    nearest_pellet(xy, s.pellet_xy, s.alive, dist_food, k)
    pk = np.take_along_axis(s.pellet_xy, np.maximum(k, 0)[..., None], axis=1) - xy   # [B, N, 2]
    out["dist_food_cm"] = dist_food
    out["bearing_food_rad"] = np.where(k >= 0, wrap(np.arctan2(pk[..., 1], pk[..., 0]) - h), np.nan)
    walls = np.stack([xy[..., 0], s.width[:, None] - xy[..., 0], xy[..., 1], s.height[:, None] - xy[..., 1]], -1)
    w = walls.argmin(axis=-1)
    out["dist_wall_cm"] = walls.min(axis=-1)
    out["bearing_wall_rad"] = wrap(np.array([np.pi, 0.0, -np.pi / 2, np.pi / 2])[w] - h)
    return out


def food_counts_reference(env: VecEnv, radius_cm: float = 5.0) -> dict[str, np.ndarray]:
    """:func:`efish.rollout.measures.food_counts`, over the [B, N, P, 2] offsets at once."""
    s = env.state
    d = s.pellet_xy[:, None, :, :] - s.xy[:, :, None, :]             # [B, N, P, 2]
    near = (np.einsum("bnpi,bnpi->bnp", d, d) <= radius_cm ** 2) & s.alive[:, None, :]
    bearing = wrap(np.arctan2(d[..., 1], d[..., 0]) - s.heading[..., None])
    sector = np.round(bearing / (np.pi / 2)).astype(int) % 4           # 0 front, 1 left, 2 back, 3 right
    out = {"food_count_5cm": near.sum(-1)}
    for k, name in enumerate(SECTORS):
        out[f"food_{name}_5cm"] = (near & (sector == k)).sum(-1)
    return out


def agents_in_range_reference(env: VecEnv, range_cm: float) -> np.ndarray:
    """:func:`efish.rollout.measures.agents_in_range`, over the [B, N, N] distances at once."""
    xy = env.state.xy
    d = np.linalg.norm(xy[:, None, :, :] - xy[:, :, None, :], axis=-1)   # [B, N(i), N(j)]
    others = ~np.eye(env.n, dtype=bool)
    return ((d < range_cm) & others).sum(-1)


def log_fields_reference(env: VecEnv) -> dict[str, np.ndarray]:
    """:func:`efish.rollout.measures.log_fields` from the physics' pairwise fields (efish.physics.fields) of
    every (agent, body) pair [B, N, N + P, 2], masked and summed."""
    s, plan, soft = env.state, env.plan, env.cfg.physics.softening_m
    xy, h = s.xy * CM, s.heading
    bodies = np.concatenate([xy, s.pellet_xy * CM], axis=1)             # [B, N + P, 2]
    n = env.n
    live = np.concatenate([np.ones(xy.shape[:2], bool), s.alive], axis=1)
    is_agent = np.arange(bodies.shape[1]) < n
    alpha = np.where(is_agent, plan.alpha_agent, plan.alpha_pellet)     # [N + P]
    centre = xy[:, :, None, :]                                          # [B, N, 1, 2]
    others = live[:, None, :] & ~np.eye(n, bodies.shape[1], dtype=bool)[None]
    p_int = intrinsic_moments(h, s.pellet_phi, plan)                    # [B, N + P, 2]
    field = {"softening": soft, "eps0": plan.eps0}
    e_amp = pairwise_dipole_field(centre, bodies[:, None], p_int[:, None], **field)    # [B, N, N + P, 2]
    e_eod = eod_field(plan, soft, xy[:, :, None, :], h[:, :, None], bodies[:, None])   # own EOD at every body
    e_morm = pairwise_dipole_field(centre, bodies[:, None], induced_dipole(alpha, e_eod), **field)
    with np.errstate(divide="ignore"):
        return {name: np.log10(np.linalg.norm((e * others[..., None]).sum(2), axis=-1))
                for name, e in (("log_amp_field", e_amp), ("log_morm_field", e_morm))}
