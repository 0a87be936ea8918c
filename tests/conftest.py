"""Shared fixtures and scene builders for the efish physics/sensing tests.

The default config is composed once per session (composition costs ~0.1 s);
configs with overrides are composed once each and cached.
"""

from __future__ import annotations

import functools

import numpy as np
import pytest

from efish import Snapshot
from efish.config import compose
from efish.physics import Scene, build_plan

RECEPTORS = ("mormyromast", "ampullary", "knollenorgan", "knollen_size")


@functools.lru_cache(maxsize=None)
def _compose_cached(overrides: tuple[str, ...]):
    return compose(list(overrides))


def cfg_with(*overrides: str):
    """The default config with Hydra overrides, composed once per distinct override set.

    The returned object is shared: never mutate it.
    """
    return _compose_cached(tuple(overrides))


@pytest.fixture(scope="session")
def default_cfg():
    """The composed default config (shared, do not mutate)."""
    return cfg_with()


@pytest.fixture(scope="session")
def cfg_factory():
    """``cfg_factory("a.b=1", ...)``: a cached composed config with overrides."""
    return cfg_with


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
