"""Food layouts and spawn positions (SPEC 6 reset, SPEC 8)."""

from __future__ import annotations

import numpy as np

from ..config.schema import ArenaConfig

AGENT_RADIUS_CM = 1.0  # bodies are 1 cm circles (SPEC 1); non-overlap means centres >= 2 cm apart


def sample_pellets(cfg: ArenaConfig, rng: np.random.Generator) -> np.ndarray:
    """Pellet positions (P, 2) in cm for one episode of the arena's layout."""
    w, h = cfg.width_cm, cfg.height_cm
    area = w * h
    m = cfg.food_multiplier
    if cfg.layout == "none":
        return np.zeros((0, 2))
    if cfg.layout == "uniform":
        count = min(rng.poisson(cfg.uniform_density * m * area), round(cfg.uniform_cap_density * m * area))
        return rng.uniform((0.0, 0.0), (w, h), size=(count, 2))
    n_patches = max(1, int(np.ceil(cfg.patch_density * area * m)))
    pellets = []
    for _ in range(n_patches):
        centre = rng.uniform((0.0, 0.0), (w, h))
        radius = float(np.clip(rng.normal(cfg.patch_radius_mean_cm, cfg.patch_radius_sd_cm), 1.0, min(w, h) / 2))
        disc = np.pi * radius ** 2
        count = min(rng.poisson(cfg.patch_pellet_density * disc), round(cfg.patch_cap_density * disc))
        pellets.append(_points_in_disc(centre, radius, count, w, h, rng))
    return np.concatenate(pellets) if pellets else np.zeros((0, 2))


def _points_in_disc(centre: np.ndarray, radius: float, count: int, w: float, h: float,
                    rng: np.random.Generator) -> np.ndarray:
    """``count`` points uniform in the part of the disc that lies inside the arena (rejection)."""
    out = np.zeros((0, 2))
    while len(out) < count:
        r = radius * np.sqrt(rng.uniform(size=2 * count))
        a = rng.uniform(0, 2 * np.pi, size=2 * count)
        p = centre + np.stack([r * np.cos(a), r * np.sin(a)], axis=1)
        inside = (p[:, 0] >= 0) & (p[:, 0] <= w) & (p[:, 1] >= 0) & (p[:, 1] <= h)
        out = np.concatenate([out, p[inside]])
    return out[:count]


def spawn_agents(n: int, width: float, height: float, margin: float, rng: np.random.Generator,
                 max_tries: int = 10_000) -> np.ndarray:
    """``n`` agent centres uniform in the arena with a wall margin and no overlap (centres >= 2 cm apart)."""
    lo, hi = (margin, margin), (width - margin, height - margin)
    xy = np.zeros((0, 2))
    for _ in range(max_tries):
        if len(xy) == n:
            return xy
        p = rng.uniform(lo, hi)
        if len(xy) == 0 or np.min(np.linalg.norm(xy - p, axis=1)) >= 2 * AGENT_RADIUS_CM:
            xy = np.vstack([xy, p])
    raise ValueError(f"could not place {n} agents without overlap in a {width:g} x {height:g} cm arena")
