"""The observation vector of SPEC 4, assembled from sensing and body state.

Layout for A observed agents (A = env.obs_agents, 110 values for A = 4):
Mormyromast 36 | Ampullary 24 | Knollenorgan (A-1) x 12 | size channel A-1 |
last action (move, turn, eod, bite) 4 | was bitten 1 | own size 1 |
bite cooldown / bite_cooldown 1 | last displacement in the body frame / v_max 2 |
eat cooldown / eat_cooldown 1 | reserved 1. Unused Knollenorgan slots are 0.
"""

from __future__ import annotations

import numpy as np

TAIL = 4 + 1 + 1 + 1 + 2 + 1 + 1  # last action .. reserved


def obs_size(n_morm: int, n_amp: int, n_knoll: int, obs_agents: int) -> int:
    """Length of one agent's observation."""
    return n_morm + n_amp + (obs_agents - 1) * (n_knoll + 1) + TAIL


def observation_slices(n_morm: int, n_amp: int, n_knoll: int, obs_agents: int) -> dict[str, slice]:
    """Where each block sits in the observation vector."""
    slots = obs_agents - 1
    edges = np.cumsum([0, n_morm, n_amp, slots * n_knoll, slots, 4, 1, 1, 1, 2, 1, 1])
    names = ("mormyromast", "ampullary", "knollenorgan", "knollen_size", "last_action", "was_bitten",
             "own_size", "bite_cooldown", "displacement", "eat_cooldown", "reserved")
    return {k: slice(int(a), int(b)) for k, a, b in zip(names, edges[:-1], edges[1:])}


def build_observation(readings: dict[str, np.ndarray], last_action: np.ndarray, was_bitten: np.ndarray,
                      size: np.ndarray, bite_cd: np.ndarray, eat_cd: np.ndarray, displacement_body: np.ndarray,
                      v_max: np.ndarray, eat_cooldown: int, bite_cooldown: int, obs_agents: int) -> np.ndarray:
    """float32[B, N, D] observations; see the module docstring for the layout."""
    b, n, sm = readings["mormyromast"].shape
    sa, sk = readings["ampullary"].shape[2], readings["knollenorgan"].shape[3]
    sl = observation_slices(sm, sa, sk, obs_agents)
    obs = np.zeros((b, n, obs_size(sm, sa, sk, obs_agents)), dtype=np.float32)
    obs[..., sl["mormyromast"]] = readings["mormyromast"]
    obs[..., sl["ampullary"]] = readings["ampullary"]
    knoll = np.zeros((b, n, obs_agents - 1, sk), dtype=np.float32)
    knoll[:, :, : n - 1] = readings["knollenorgan"]
    obs[..., sl["knollenorgan"]] = knoll.reshape(b, n, -1)
    obs[..., sl["knollen_size"].start: sl["knollen_size"].start + n - 1] = readings["knollen_size"]
    obs[..., sl["last_action"]] = last_action
    obs[..., sl["was_bitten"]] = was_bitten[..., None]
    obs[..., sl["own_size"]] = size[..., None]
    obs[..., sl["bite_cooldown"]] = (bite_cd / max(bite_cooldown, 1))[..., None]
    obs[..., sl["displacement"]] = np.clip(displacement_body / np.maximum(v_max, 1e-12)[..., None], -1, 1)
    obs[..., sl["eat_cooldown"]] = (eat_cd / max(eat_cooldown, 1))[..., None]
    return obs
