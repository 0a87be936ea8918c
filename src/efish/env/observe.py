"""The observation vector of SPEC 4, assembled from perception and body state.

Electric perception, for A observed agents (A = env.obs_agents, 110 values for A = 4):
Mormyromast 36 | Ampullary 24 | Knollenorgan (A-1) x 12 | size channel A-1 | tail.
Ray casting: ray proximity R | ray kind R | tail (83 values for R = 36).
Tail: last action (move, turn, eod, bite) 4 | was bitten 1 | own size 1 |
bite cooldown / bite_cooldown 1 | last displacement in the body frame / v_max 2 |
eat cooldown / eat_cooldown 1 | reserved 1. Unused Knollenorgan slots are 0.
"""

from __future__ import annotations

import numpy as np

TAIL_NAMES = ("last_action", "was_bitten", "own_size", "bite_cooldown", "displacement", "eat_cooldown", "reserved")
TAIL_SIZES = (4, 1, 1, 1, 2, 1, 1)


def _slices(names, sizes) -> dict[str, slice]:
    edges = np.cumsum((0,) + tuple(sizes))
    return {k: slice(int(a), int(b)) for k, a, b in zip(names, edges[:-1], edges[1:])}


def observation_slices(n_morm: int, n_amp: int, n_knoll: int, obs_agents: int) -> dict[str, slice]:
    """Where each block sits in the electric observation vector."""
    slots = obs_agents - 1
    return _slices(("mormyromast", "ampullary", "knollenorgan", "knollen_size") + TAIL_NAMES,
                   (n_morm, n_amp, slots * n_knoll, slots) + TAIL_SIZES)


def ray_observation_slices(n_rays: int) -> dict[str, slice]:
    """Where each block sits in the ray-casting observation vector."""
    return _slices(("ray_proximity", "ray_kind") + TAIL_NAMES, (n_rays, n_rays) + TAIL_SIZES)


def electric_block(readings: dict[str, np.ndarray], obs_agents: int) -> np.ndarray:
    """float32[B, N, 36 + 24 + 13 (A-1)]: receptor readings, Knollenorgan slots padded to A-1."""
    b, n, _ = readings["mormyromast"].shape
    sk = readings["knollenorgan"].shape[3]
    knoll = np.zeros((b, n, obs_agents - 1, sk), dtype=np.float32)
    knoll[:, :, : n - 1] = readings["knollenorgan"]
    size = np.zeros((b, n, obs_agents - 1), dtype=np.float32)
    size[:, :, : n - 1] = readings["knollen_size"]
    return np.concatenate([readings["mormyromast"], readings["ampullary"], knoll.reshape(b, n, -1), size],
                          axis=-1).astype(np.float32)


def tail_block(last_action: np.ndarray, was_bitten: np.ndarray, size: np.ndarray, bite_cd: np.ndarray,
               eat_cd: np.ndarray, displacement_body: np.ndarray, v_max: np.ndarray, eat_cooldown: int,
               bite_cooldown: int) -> np.ndarray:
    """float32[B, N, 11]: proprioception and internal state."""
    disp = np.clip(displacement_body / np.maximum(v_max, 1e-12)[..., None], -1, 1)
    return np.concatenate([
        last_action, was_bitten[..., None], size[..., None], (bite_cd / max(bite_cooldown, 1))[..., None],
        disp, (eat_cd / max(eat_cooldown, 1))[..., None], np.zeros(was_bitten.shape + (1,)),
    ], axis=-1).astype(np.float32)
