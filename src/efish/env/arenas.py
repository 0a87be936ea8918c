"""Arenas and food: layouts, per-episode sampling, regrowth and drift (docs/model/environment.md#arenas-and-food;
reset: docs/model/environment.md#step-order).

Every function takes the arena config and a ``numpy.random.Generator``; none
keeps state. Positions are in cm, angles in radians.
"""

from __future__ import annotations

import dataclasses

import numpy as np

from .._jit import njit
from ..config.schema import ArenaConfig


def sample_arena(cfg: ArenaConfig, rng: np.random.Generator) -> ArenaConfig:
    """The arena of one episode: ``cfg`` itself, or for ``layout=training`` a sampled one.

    Training: W, H each min + span * u^exponent (u ~ U(0, 1)); patchy, uniform or
    no food with odds patchy : uniform : none weights; food multiplier log-uniform.
    """
    if cfg.layout != "training":
        return cfg
    w, h = cfg.train_size_min_cm + cfg.train_size_span_cm * rng.uniform(size=2) ** cfg.train_size_exponent
    weights = np.array([cfg.train_patchy_weight, cfg.train_uniform_weight, cfg.train_none_weight])
    layout = ("patchy", "uniform", "none")[int(np.searchsorted(np.cumsum(weights) / weights.sum(), rng.uniform(),
                                                                side="right"))]
    m = np.exp(rng.uniform(np.log(cfg.train_multiplier_min), np.log(cfg.train_multiplier_max)))
    return dataclasses.replace(cfg, layout=layout, width_cm=float(w), height_cm=float(h), food_multiplier=float(m))


def patch_count(cfg: ArenaConfig) -> int:
    """Patches of the patchy layout: max(1, round(m * ceil(density * area))).

    70 x 70: m = 1 -> 5, 0.5 -> 2, 0.25 -> 1 (docs/model/environment.md#arenas-and-food; round half to even).
    """
    base = int(np.ceil(cfg.patch_density * cfg.width_cm * cfg.height_cm))
    return max(1, int(round(cfg.food_multiplier * base)))


def npatch_centres(cfg: ArenaConfig, rng: np.random.Generator) -> np.ndarray:
    """Centres (n, 2) of the N-patch layout: the arena centre for n = 1, else evenly on an
    ellipse of semi-axes ring_fraction * (W/2, H/2) from a random start angle."""
    n = cfg.npatch_count
    centre = np.array([cfg.width_cm, cfg.height_cm]) / 2
    if n == 1:
        return centre[None, :]
    angles = rng.uniform(0, 2 * np.pi) + 2 * np.pi * np.arange(n) / n
    semi = cfg.npatch_ring_fraction * centre
    return centre + semi * np.stack([np.cos(angles), np.sin(angles)], axis=1)


def sample_pellets(cfg: ArenaConfig, rng: np.random.Generator) -> np.ndarray:
    """Pellet positions (P, 2) in cm at the start of an episode of the arena's layout."""
    w, h, m = cfg.width_cm, cfg.height_cm, cfg.food_multiplier
    area = w * h
    if cfg.layout == "training":
        raise ValueError("arena.layout=training must be resolved with sample_arena() first")
    if cfg.layout == "none":
        return np.zeros((0, 2))
    if cfg.layout == "uniform":
        count = min(rng.poisson(cfg.uniform_density * m * area), round(cfg.uniform_cap_density * m * area))
        return rng.uniform((0.0, 0.0), (w, h), size=(count, 2))
    if cfg.layout == "onepatch":
        centre = np.array([w, h]) / 2
        count = min(rng.poisson(cfg.onepatch_initial_mean), cfg.onepatch_cap)
        return points_in_disc(centre, cfg.onepatch_radius_cm, count, w, h, rng)
    if cfg.layout == "npatch":
        r = cfg.npatch_radius_cm
        mean = cfg.patch_pellet_density * m * np.pi * r ** 2
        return _concat([points_in_disc(c, r, rng.poisson(mean), w, h, rng) for c in npatch_centres(cfg, rng)])
    pellets = []
    for _ in range(patch_count(cfg)):
        centre = rng.uniform((0.0, 0.0), (w, h))
        radius = float(np.clip(rng.normal(cfg.patch_radius_mean_cm, cfg.patch_radius_sd_cm),
                               cfg.patch_radius_min_cm, min(w, h) / 2))
        disc = np.pi * radius ** 2
        count = min(rng.poisson(cfg.patch_pellet_density * disc), round(cfg.patch_cap_density * disc))
        pellets.append(points_in_disc(centre, radius, count, w, h, rng))
    return _concat(pellets)


def regrow_onepatch(cfg: ArenaConfig, n_alive: int, rng: np.random.Generator) -> np.ndarray:
    """New pellets (k, 2) of one step of one-patch regrowth: Poisson(regrow_mean), never above the cap."""
    if cfg.layout != "onepatch":
        return np.zeros((0, 2))
    count = min(rng.poisson(cfg.onepatch_regrow_mean), max(0, cfg.onepatch_cap - n_alive))
    if count == 0:  # the common case once the patch is full: nothing more to draw
        return np.zeros((0, 2))
    centre = np.array([cfg.width_cm, cfg.height_cm]) / 2
    return points_in_disc(centre, cfg.onepatch_radius_cm, count, cfg.width_cm, cfg.height_cm, rng)


def drift_orientations(phi: np.ndarray, sd: float | np.ndarray, rng: np.random.Generator,
                       out: np.ndarray | None = None) -> np.ndarray:
    """Pellet orientations after one step of drift N(0, sd) (``sd`` broadcasts), wrapped to [0, 2 pi).

    ``out`` (may be ``phi`` itself) receives the result without temporaries.
    Equals ``np.mod(phi + sd * z, 2 pi)`` with ``z = rng.standard_normal(phi.shape)``, bit for bit.
    """
    z = rng.standard_normal(np.shape(phi))
    z *= sd
    z += phi
    out = np.empty(np.shape(phi)) if out is None else out
    _wrap_2pi(z.reshape(-1), out.reshape(-1))
    return out


@njit(cache=True)
def _wrap_2pi(x, out):
    """``out = np.mod(x, 2 pi)`` bit for bit, without numpy's fmod for the usual |x| < 4 pi.

    fmod is exact, so for x in [2 pi, 4 pi) it equals x - 2 pi (exact by Sterbenz),
    for x in (-2 pi, 0) numpy adds 2 pi to x, and a zero result is +0.0.
    """
    period = 2 * np.pi
    for k in range(x.size):
        v = x[k]
        if v == 0.0:
            out[k] = 0.0
        elif 0.0 < v < period:
            out[k] = v
        elif period <= v < 2 * period:
            out[k] = v - period
        elif -period < v < 0.0:
            out[k] = v + period
        else:
            out[k] = v % period  # numba's float % follows the same fmod-and-adjust rule as np.mod


def points_in_disc(centre: np.ndarray, radius: float, count: int, w: float, h: float,
                   rng: np.random.Generator) -> np.ndarray:
    """``count`` points uniform in the part of the disc that lies inside the arena (rejection).

    Each round draws 2 ``count`` radii and angles and keeps, in order, the points inside the arena.
    """
    out = np.empty((count, 2))
    kept = 0
    while kept < count:
        u = rng.uniform(size=2 * count)
        a = rng.uniform(0, 2 * np.pi, size=2 * count)
        kept = _keep_inside(float(centre[0]), float(centre[1]), radius, u, a, w, h, out, kept)
    return out


@njit(cache=True)
def _keep_inside(cx, cy, radius, u, angle, w, h, out, kept):
    """Append to ``out[kept:]`` the points (radius sqrt(u), angle) around (cx, cy) that lie in [0, w] x [0, h];
    returns the new count (stops when ``out`` is full)."""
    for k in range(u.size):
        if kept == out.shape[0]:
            break
        r = radius * np.sqrt(u[k])
        x, y = cx + r * np.cos(angle[k]), cy + r * np.sin(angle[k])
        if 0.0 <= x <= w and 0.0 <= y <= h:
            out[kept, 0], out[kept, 1] = x, y
            kept += 1
    return kept


def _concat(parts: list[np.ndarray]) -> np.ndarray:
    return np.concatenate(parts) if parts else np.zeros((0, 2))


def spawn_agents(n: int, width: float, height: float, margin: float, radius: float, rng: np.random.Generator,
                 max_tries: int = 10_000, first: np.ndarray | None = None) -> np.ndarray:
    """``n`` agent centres uniform in the arena with a wall margin and no overlap (centres >= 2 radii apart).

    ``first`` (k, 2): centres already placed; they are kept as the first k rows.
    """
    lo, hi = (margin, margin), (width - margin, height - margin)
    xy = np.zeros((0, 2)) if first is None else np.asarray(first, dtype=float).reshape(-1, 2)
    for _ in range(max_tries):
        if len(xy) == n:
            return xy
        p = rng.uniform(lo, hi)
        if len(xy) == 0 or np.min(np.linalg.norm(xy - p, axis=1)) >= 2 * radius:
            xy = np.vstack([xy, p])
    raise ValueError(f"could not place {n} agents without overlap in a {width:g} x {height:g} cm arena")
