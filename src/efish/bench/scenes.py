"""Benchmark snapshots: 4 agents in the default 70 x 70 patchy arena.

Half the snapshots are as at reset (agents uniform), half are foraging states
(each agent within 10 cm of a pellet), because that is where the field
computation does its real work: an arena where nobody is near anything is
nearly free thanks to the exact zero shortcut.
"""

from __future__ import annotations

import numpy as np

from ..config.schema import EfishConfig
from ..env.arenas import sample_pellets, spawn_agents
from ..physics.snapshot import Snapshot, SnapshotBatch


def benchmark_snapshot(cfg: EfishConfig, rng: np.random.Generator, foraging: bool) -> Snapshot:
    """One 4-agent patchy snapshot; ``foraging`` puts every agent near a pellet."""
    a = cfg.arena
    n = cfg.env.n_agents
    pellets = sample_pellets(a, rng)
    r = cfg.physics.agent_radius_cm
    xy = spawn_agents(n, a.width_cm, a.height_cm, a.wall_margin_cm, r, rng)
    if foraging and len(pellets):
        for i in range(n):
            for _ in range(100):
                target = pellets[rng.integers(len(pellets))]
                p = np.clip(target + rng.uniform(-10, 10, 2), a.wall_margin_cm,
                            (a.width_cm - a.wall_margin_cm, a.height_cm - a.wall_margin_cm))
                others = np.delete(xy, i, axis=0)
                if np.min(np.linalg.norm(others - p, axis=1), initial=np.inf) >= 2 * r:
                    xy[i] = p
                    break
    return Snapshot(agent_xy=xy, agent_heading=rng.uniform(-np.pi, np.pi, n),
                    agent_size=rng.uniform(0, 1, n), agent_emitting=rng.uniform(size=n) < 0.5,
                    pellet_xy=pellets, pellet_orientation=rng.uniform(0, 2 * np.pi, len(pellets)),
                    width=a.width_cm, height=a.height_cm)


def benchmark_batch(cfg: EfishConfig, count: int, seed: int) -> SnapshotBatch:
    """``count`` snapshots, alternating reset-like and foraging states, as one batch."""
    rng = np.random.default_rng(seed)
    return SnapshotBatch.stack([benchmark_snapshot(cfg, rng, foraging=bool(i % 2)) for i in range(count)])
