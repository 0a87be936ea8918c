"""Shared helpers of the efish tests: cached configs, scene builders, env drivers, invariants.

Test modules import these (``from ..helpers import cfg_with``); ``conftest.py``
only holds fixtures. Configs are composed once per distinct override set
(composition costs ~0.1 s).
"""

from __future__ import annotations

import functools

import numpy as np

from efish import Snapshot
from efish.config import compose
from efish.physics import Scene, build_plan

RECEPTORS = ("mormyromast", "ampullary", "knollenorgan", "knollen_size")
BIG = 40.0  # raw action whose sigmoid / tanh is 1 to double precision


@functools.lru_cache(maxsize=None)
def _compose_cached(overrides: tuple[str, ...]):
    return compose(list(overrides))


def cfg_with(*overrides: str):
    """The default config with Hydra overrides, composed once per distinct override set.

    The returned object is shared: never mutate it.
    """
    return _compose_cached(tuple(overrides))


def random_snapshot(rng: np.random.Generator, n_agents: int, n_pellets: int, width: float = 70.0,
                    height: float = 70.0, emitting: np.ndarray | None = None, margin: float = 1.0) -> Snapshot:
    """A random arena: agents and pellets uniform in [margin, W - margin] x [margin, H - margin]."""
    def pts(k):
        return np.column_stack([rng.uniform(margin, width - margin, k), rng.uniform(margin, height - margin, k)])
    if emitting is None:
        emitting = rng.random(n_agents) < 0.5
    return Snapshot(agent_xy=pts(n_agents), agent_heading=rng.uniform(-np.pi, np.pi, n_agents),
                    agent_size=rng.uniform(0, 1, n_agents), agent_emitting=emitting,
                    pellet_xy=pts(n_pellets), pellet_orientation=rng.uniform(0, 2 * np.pi, n_pellets),
                    width=width, height=height)


def plan_for(cfg, snapshot: Snapshot, **kw):
    """The plan ``efish.sense`` would build for this snapshot."""
    return build_plan(cfg, Scene.of_batch(snapshot.as_batch()), **kw)


def assert_valid_readings(r: dict, n_agents: int) -> None:
    """Shapes, finiteness and ranges every ``efish.sense`` result must satisfy."""
    n = n_agents
    assert r["mormyromast"].shape == (n, 36)
    assert r["ampullary"].shape == (n, 24)
    assert r["knollenorgan"].shape == (n, n - 1, 12)
    assert r["knollen_size"].shape == (n, n - 1)
    for name in RECEPTORS:
        v = r[name]
        assert np.all(np.isfinite(v)), name
        assert np.all(np.abs(v) <= 1.0), name
    assert set(np.unique(r["knollenorgan"])) <= {-1.0, 0.0, 1.0}
    size = r["knollen_size"]
    assert np.all((size == 0) | ((size >= 0.5) & (size <= 1.0)))


def make_env(*overrides: str, num_envs: int = 1, seed: int = 0):
    """A ``VecEnv`` of the default config with overrides."""
    from efish.env import VecEnv

    return VecEnv(compose(list(overrides)), num_envs=num_envs, seed=seed)


def actions(env, move=-BIG, turn=0.0, eod=0, bite=0) -> np.ndarray:
    """The same raw action for every agent of every arena: float64[B, N, 4]."""
    a = np.zeros((env.num_envs, env.n, 4))
    a[..., 0], a[..., 1], a[..., 2], a[..., 3] = move, turn, eod, bite
    return a


def random_actions(rng: np.random.Generator, num_envs: int, n_agents: int) -> np.ndarray:
    """Gaussian move/turn and 0/1 eod/bite for every agent: float64[B, N, 4]."""
    return np.concatenate([rng.normal(size=(num_envs, n_agents, 2)), rng.integers(0, 2, (num_envs, n_agents, 2))],
                          axis=-1)
