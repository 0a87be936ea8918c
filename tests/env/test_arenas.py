"""Food layouts and arena sampling against their statistics (docs/model/environment.md#arenas-and-food)."""

from __future__ import annotations

import dataclasses
import functools

import numpy as np
import pytest
from scipy import stats

from efish.config import compose
from efish.env.arenas import (
    drift_orientations,
    npatch_centres,
    patch_count,
    regrow_onepatch,
    sample_arena,
    sample_pellets,
    spawn_agents,
)

RESETS = 400


@functools.lru_cache(maxsize=None)
def _arena(name: str):
    return compose([f"arena={name}"]).arena


def arena(name: str, **changes):
    return dataclasses.replace(_arena(name), **changes)


def poisson_mean_ok(counts: np.ndarray, mean: float) -> bool:
    """Two-sided test of the sample mean of Poisson counts (normal approximation, alpha 1e-4)."""
    z = (counts.mean() - mean) / np.sqrt(mean / len(counts))
    return abs(z) < 3.9


def inside(p: np.ndarray, cfg) -> bool:
    return bool(np.all((p >= 0) & (p <= [cfg.width_cm, cfg.height_cm])))


@pytest.mark.parametrize("m, expected", [(1.0, 5), (0.5, 2), (0.25, 1)])
def test_patch_count_follows_the_multiplier(m, expected):
    assert patch_count(arena("patchy70", food_multiplier=m)) == expected


def test_uniform_pellet_count_is_poisson_with_the_spec_mean():
    cfg = arena("uniform70")  # mean 0.0045 * 4900 = 22.05, cap round(0.005 * 4900) = 24.5 -> 24
    rng = np.random.default_rng(0)
    counts = np.array([len(sample_pellets(cfg, rng)) for _ in range(RESETS)])
    cap = round(cfg.uniform_cap_density * 4900)
    assert counts.max() <= cap
    # the cap truncates: compare with the mean of min(Poisson, cap)
    k = np.arange(cap + 1)
    truncated = (k * stats.poisson.pmf(k, 22.05)).sum() + cap * stats.poisson.sf(cap, 22.05)
    assert abs(counts.mean() - truncated) < 4 * counts.std() / np.sqrt(RESETS)


def test_one_patch_start_and_regrowth_respect_mean_and_cap():
    cfg = arena("onepatch")
    rng = np.random.default_rng(1)
    start = np.array([len(sample_pellets(cfg, rng)) for _ in range(RESETS)])
    assert poisson_mean_ok(start, 11.3)
    grown = np.array([len(regrow_onepatch(cfg, 0, rng)) for _ in range(RESETS)])
    assert poisson_mean_ok(grown, 1.13)
    assert len(regrow_onepatch(cfg, cfg.onepatch_cap, rng)) == 0
    assert all(len(regrow_onepatch(cfg, cfg.onepatch_cap - 1, rng)) <= 1 for _ in range(200))
    p = sample_pellets(cfg, rng)
    assert np.all(np.linalg.norm(p - [75, 75], axis=1) <= cfg.onepatch_radius_cm + 1e-9)


def test_no_regrowth_outside_the_one_patch_layout():
    assert len(regrow_onepatch(arena("patchy70"), 0, np.random.default_rng(0))) == 0


def test_patchy_pellets_lie_inside_the_arena_and_scale_with_patches():
    rng = np.random.default_rng(2)
    for name in ("patchy70", "wide", "collective"):
        cfg = arena(name, layout="patchy")
        for _ in range(50):
            assert inside(sample_pellets(cfg, rng), cfg)
    full = np.mean([len(sample_pellets(arena("patchy70"), rng)) for _ in range(RESETS)])
    quarter = np.mean([len(sample_pellets(arena("patchy70", food_multiplier=0.25), rng)) for _ in range(RESETS)])
    assert 3.5 < full / quarter < 6.5  # 5 patches against 1


@pytest.mark.parametrize("n", [1, 2, 3, 5])
def test_npatch_geometry(n):
    cfg = arena("npatch", npatch_count=n)
    c = npatch_centres(cfg, np.random.default_rng(n))
    assert c.shape == (n, 2)
    if n == 1:
        np.testing.assert_allclose(c[0], [35, 35])
        return
    r = np.linalg.norm(c - 35, axis=1)
    np.testing.assert_allclose(r, 26.25)  # on the ellipse (a circle in a square arena)
    ang = np.sort(np.mod(np.arctan2(c[:, 1] - 35, c[:, 0] - 35), 2 * np.pi))
    gaps = np.diff(np.concatenate([ang, ang[:1] + 2 * np.pi]))
    np.testing.assert_allclose(gaps, 2 * np.pi / n)  # evenly spaced


def test_npatch_iso_series_keeps_total_food():
    rng = np.random.default_rng(3)
    means = []
    for n in (1, 2, 4):
        cfg = arena("npatch", npatch_count=n, food_multiplier=1.0 / n)
        means.append(np.mean([len(sample_pellets(cfg, rng)) for _ in range(RESETS)]))
    expected = 0.15 * np.pi * 7.5 ** 2  # 26.5 in total whatever n
    for mean in means:
        assert abs(mean - expected) < 4 * np.sqrt(expected / RESETS)


def test_training_arenas_follow_their_distributions():
    cfg = arena("training")
    rng = np.random.default_rng(4)
    draws = [sample_arena(cfg, rng) for _ in range(2000)]
    w = np.array([d.width_cm for d in draws])
    assert w.min() >= 40 and w.max() <= 300
    assert abs(w.mean() - (40 + 260 / 4)) < 4 * w.std() / np.sqrt(len(w))  # E[u^3] = 1/4
    patchy = sum(d.layout == "patchy" for d in draws)
    assert stats.binomtest(patchy, len(draws), 5 / 6).pvalue > 1e-4
    m = np.array([d.food_multiplier for d in draws])
    assert m.min() >= 0.5 and m.max() <= 2.0
    assert abs(np.log(m).mean()) < 4 * np.log(m).std() / np.sqrt(len(m))  # log-uniform, centred on 1


def test_training_layout_must_be_resolved_first():
    with pytest.raises(ValueError, match="sample_arena"):
        sample_pellets(arena("training"), np.random.default_rng(0))


def test_orientation_drift_has_the_configured_spread():
    cfg = arena("patchy70")
    phi = np.full(20000, np.pi)
    step = drift_orientations(phi, cfg.orientation_drift_rad, np.random.default_rng(5)) - np.pi
    assert abs(step.std() - 0.1) < 0.005 and abs(step.mean()) < 0.005


def test_spawned_agents_keep_the_margin_and_never_overlap():
    rng = np.random.default_rng(6)
    for _ in range(100):
        xy = spawn_agents(4, 10.0, 10.0, 1.0, 1.0, rng)
        assert np.all((xy >= 1) & (xy <= 9))
        d = np.linalg.norm(xy[:, None] - xy[None], axis=-1) + np.eye(4) * 99
        assert d.min() >= 2.0


def test_spawning_too_many_agents_fails_with_a_clear_error():
    with pytest.raises(ValueError, match="could not place"):
        spawn_agents(50, 5.0, 5.0, 1.0, 1.0, np.random.default_rng(0), max_tries=2000)


def test_homing_training_arenas_have_no_food_and_span_75_to_150_cm():
    cfg = arena("homing_train")
    rng = np.random.default_rng(9)
    draws = [sample_arena(cfg, rng) for _ in range(500)]
    assert all(d.layout == "none" and len(sample_pellets(d, rng)) == 0 for d in draws)
    w = np.array([d.width_cm for d in draws])
    assert w.min() >= 75 and w.max() <= 150 and abs(w.mean() - 112.5) < 3
