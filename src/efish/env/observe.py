"""The observation vector (docs/model/environment.md#observation), assembled from perception and body state.

Electric perception, for A observed agents (A = env.obs_agents, 110 values for A = 4):
Mormyromast 36 | Ampullary 24 | Knollenorgan (A-1) x 12 | size channel A-1 | tail.
Ray casting: ray proximity R | ray kind R | tail (83 values for R = 36).
Tail: last action (move, turn, eod, bite) 4 | was bitten 1 | own size 1 |
bite cooldown / bite_cooldown 1 | last displacement in the body frame / v_max 2 |
eat cooldown / eat_cooldown 1 | reserved 1. Unused Knollenorgan slots are 0.
"""

from __future__ import annotations

import numpy as np

from .._jit import njit
from ..config.schema import EfishConfig
from ..sensors.encode import electric_width

TAIL_NAMES = ("last_action", "was_bitten", "own_size", "bite_cooldown", "displacement", "eat_cooldown", "reserved")
TAIL_SIZES = (4, 1, 1, 1, 2, 1, 1)


def _slices(names, sizes) -> dict[str, slice]:
    edges = np.cumsum((0,) + tuple(sizes))
    return {k: slice(int(a), int(b)) for k, a, b in zip(names, edges[:-1], edges[1:], strict=True)}


def perception_width(cfg: EfishConfig) -> int:
    """Length of the sensory block: the electric receptors (docs/model/environment.md#observation) or the rays of the
    baseline."""
    se = cfg.sensors
    if se.perception == "raycast":
        return 2 * se.ray_count
    return electric_width(se.mormyromast.count, se.ampullary.count, se.knollenorgan.count, cfg.env.obs_agents - 1)


def observation_size(cfg: EfishConfig) -> int:
    """Length of one agent's observation vector (110 with the defaults, 83 with ray casting)."""
    return perception_width(cfg) + sum(TAIL_SIZES)


def observation_slices(n_morm: int, n_amp: int, n_knoll: int, obs_agents: int) -> dict[str, slice]:
    """Where each block sits in the electric observation vector."""
    slots = obs_agents - 1
    return _slices(("mormyromast", "ampullary", "knollenorgan", "knollen_size") + TAIL_NAMES,
                   (n_morm, n_amp, slots * n_knoll, slots) + TAIL_SIZES)


def ray_observation_slices(n_rays: int) -> dict[str, slice]:
    """Where each block sits in the ray-casting observation vector."""
    return _slices(("ray_proximity", "ray_kind") + TAIL_NAMES, (n_rays, n_rays) + TAIL_SIZES)


@njit(cache=True)
def tail_kernel(last_action, was_bitten, size, bite_cd, eat_cd, displacement_body, v_max, eat_cooldown,
                bite_cooldown, out, start):
    """Write the tail of every agent into ``out[:, :, start:start + 11]`` (float32[B, N, D]).

    Values are computed in float64 and rounded once to float32, like the
    numpy composition they replace; the displacement is divided by
    max(v_max, 1e-12) so a frozen agent reads 0, not NaN.
    """
    bite_div, eat_div = float(max(bite_cooldown, 1)), float(max(eat_cooldown, 1))
    for b in range(out.shape[0]):
        for i in range(out.shape[1]):
            o = out[b, i]
            for k in range(4):
                o[start + k] = last_action[b, i, k]
            o[start + 4] = was_bitten[b, i]
            o[start + 5] = size[b, i]
            o[start + 6] = bite_cd[b, i] / bite_div
            v = max(v_max[b, i], 1e-12)
            for k in range(2):
                o[start + 7 + k] = min(max(displacement_body[b, i, k] / v, -1.0), 1.0)
            o[start + 9] = eat_cd[b, i] / eat_div
            o[start + 10] = 0.0
