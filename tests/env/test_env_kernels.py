"""Numba kernels of the env step against the numpy formulas they replaced, bit for bit (-0.0 included).

The numpy versions below are the oracles: the observation tail
(docs/model/environment.md#observation), the foraging rewards
(docs/model/environment.md#rewards), the body-frame displacement and np.mod for the orientation drift.
"""

from __future__ import annotations

import numpy as np

from efish.config import compose
from efish.env import VecEnv
from efish.env.arenas import _wrap_2pi, drift_orientations, points_in_disc
from efish.env.dynamics import record_motion
from efish.env.observe import TAIL_SIZES, tail_kernel
from efish.env.tasks.foraging import FORAGING_PARTS, foraging_rewards


def assert_bits(got: np.ndarray, want: np.ndarray) -> None:
    assert got.dtype == want.dtype and got.shape == want.shape
    kind = {4: np.uint32, 8: np.uint64}[got.dtype.itemsize]
    np.testing.assert_array_equal(got.view(kind), want.view(kind))


def test_tail_kernel_equals_the_numpy_tail():
    rng = np.random.default_rng(0)
    b, n, eat_cd_max, bite_cd_max = 6, 4, 3, 5
    last_action = np.concatenate([rng.uniform(0, 1, (b, n, 1)), rng.uniform(-1, 1, (b, n, 1)),
                                  rng.integers(0, 2, (b, n, 2))], -1)
    was_bitten, size = rng.random((b, n)) < 0.3, rng.uniform(0, 1, (b, n))
    bite_cd, eat_cd = rng.integers(0, bite_cd_max + 1, (b, n)), rng.integers(0, eat_cd_max + 1, (b, n))
    v_max = rng.uniform(0.5, 2, (b, n))
    v_max[0] = 0.0  # frozen agents: displacement reads 0, not NaN
    disp = rng.uniform(-3, 3, (b, n, 2))
    disp[0] = 0.0
    disp[1, 0] = -0.0
    want = np.concatenate([
        last_action, was_bitten[..., None], size[..., None], (bite_cd / bite_cd_max)[..., None],
        np.clip(disp / np.maximum(v_max, 1e-12)[..., None], -1, 1), (eat_cd / eat_cd_max)[..., None],
        np.zeros((b, n, 1))], -1).astype(np.float32)
    out = np.full((b, n, 7 + sum(TAIL_SIZES)), np.nan, np.float32)
    tail_kernel(last_action, was_bitten, size, bite_cd, eat_cd, disp, v_max, eat_cd_max, bite_cd_max, out, 7)
    assert_bits(out[..., 7:], want)
    assert np.all(np.isnan(out[..., :7]))


def numpy_foraging(c, ate, d_prev, d_now, perimeter, penalty_bitten, bit, collided, move, turn):
    """Foraging reward components (docs/model/environment.md#rewards) as whole-array numpy expressions, summed with
    Python's ``sum``."""
    shaping = (d_prev - d_now) / perimeter[:, None]
    parts = {
        "food": c.reward_food * ate,
        "shaping": c.reward_shaping * np.where(np.isfinite(shaping), shaping, 0.0),
        "bitten": -c.penalty_bitten * penalty_bitten,
        "bite": -c.penalty_bite * bit,
        "collision": -c.penalty_collision * collided,
        "effort": -c.penalty_effort * (np.maximum(0.0, np.abs(move) - c.effort_free)
                                       + np.maximum(0.0, np.abs(turn) - c.effort_free)),
    }
    parts["total"] = sum(parts.values())
    return parts


def test_foraging_kernel_equals_the_numpy_rewards():
    cfg = compose().env
    rng = np.random.default_rng(1)
    b, n = 8, 4
    ate, bit, collided = (rng.random((b, n)) < 0.3 for _ in range(3))
    d_prev, d_now = rng.uniform(0, 50, (b, n)), rng.uniform(0, 50, (b, n))
    d_prev[0, 0], d_now[0, 1], d_now[1] = np.nan, np.nan, d_prev[1]  # no food left; no progress
    width, height = rng.uniform(40, 300, b), rng.uniform(40, 300, b)
    penalty = np.where(rng.random((b, n)) < 0.2, rng.uniform(0, 2, (b, n)), 0.0)
    move, turn = rng.uniform(0, 1, (b, n)), rng.uniform(-1, 1, (b, n))
    move[0, :2], turn[0, 2] = 0.5, -0.5  # effort exactly at the free threshold
    got = foraging_rewards(cfg, ate, d_prev, d_now, width, height, penalty, bit, collided, move, turn)
    want = numpy_foraging(cfg, ate, d_prev, d_now, 2 * (width + height), penalty, bit, collided, move, turn)
    assert tuple(got) == FORAGING_PARTS == tuple(want)
    for k in FORAGING_PARTS:
        assert_bits(got[k], want[k])


def test_record_motion_equals_the_numpy_body_frame():
    rng = np.random.default_rng(2)
    xy, old = rng.uniform(0, 70, (5, 3, 2)), rng.uniform(0, 70, (5, 3, 2))
    old[0] = xy[0]  # did not move
    heading = rng.uniform(-np.pi, np.pi, (5, 3))
    move, turn = rng.uniform(0, 1, (5, 3)), rng.uniform(-1, 1, (5, 3))
    eod, bite = rng.random((5, 3)) < 0.5, rng.random((5, 3)) < 0.5
    disp, last = np.full((5, 3, 2), np.nan), np.full((5, 3, 4), np.nan)
    record_motion(xy, old, heading, move, turn, eod, bite, disp, last)
    d, c, s = xy - old, np.cos(heading), np.sin(heading)
    assert_bits(disp, np.stack([c * d[..., 0] + s * d[..., 1], -s * d[..., 0] + c * d[..., 1]], -1))
    assert_bits(last, np.stack([move, turn, eod, bite], -1).astype(np.float64))


def test_wrap_equals_np_mod_including_edges():
    p = 2 * np.pi
    edges = [0.0, -0.0, p, -p, 2 * p, 3 * p, np.nextafter(p, 0), np.nextafter(p, 9), np.nextafter(2 * p, 0),
             -1e-300, 1e-300, -5e-324, np.nextafter(-p, 0), np.nextafter(-p, -9), 1e300, -1e300]
    x = np.concatenate([np.random.default_rng(3).uniform(-30, 30, 100_000), edges])
    out = np.empty_like(x)
    _wrap_2pi(x, out)
    assert_bits(out, np.mod(x, p))


def test_drift_in_place_equals_the_numpy_formula():
    phi = np.random.default_rng(4).uniform(0, 2 * np.pi, (4, 30))
    sd = np.array([0.1, 0.0, 0.5, 3.0])[:, None]
    want = np.mod(phi + sd * np.random.default_rng(5).standard_normal(phi.shape), 2 * np.pi)
    got = phi.copy()
    drift_orientations(got, sd, np.random.default_rng(5), out=got)
    assert_bits(got, want)
    assert_bits(drift_orientations(phi, sd, np.random.default_rng(5)), want)


def numpy_points_in_disc(centre, radius, count, w, h, rng):
    """Rejection sampling in the disc, as whole-array numpy rounds (same draws as ``points_in_disc``)."""
    out = np.zeros((0, 2))
    while len(out) < count:
        r = radius * np.sqrt(rng.uniform(size=2 * count))
        a = rng.uniform(0, 2 * np.pi, size=2 * count)
        p = centre + np.stack([r * np.cos(a), r * np.sin(a)], axis=1)
        inside = (p[:, 0] >= 0) & (p[:, 0] <= w) & (p[:, 1] >= 0) & (p[:, 1] <= h)
        out = np.concatenate([out, p[inside]])
    return out[:count]


def test_points_in_disc_equals_the_numpy_rejection_sampler():
    # discs well inside, across a wall and in a corner (most draws rejected, several rounds)
    for centre, count in (((35.0, 35.0), 40), ((1.0, 30.0), 25), ((0.0, 0.0), 30), ((69.5, 70.0), 1), ((5, 5), 0)):
        got = points_in_disc(np.array(centre), 6.0, count, 70.0, 70.0, a := np.random.default_rng(count))
        want = numpy_points_in_disc(np.array(centre), 6.0, count, 70.0, 70.0, b := np.random.default_rng(count))
        assert_bits(got, want)
        assert a.random() == b.random()


def test_reference_physics_env_matches_the_fast_env_closely():
    cfg = compose(["arena=patchy70", "env.episode_steps=50"])
    fast, ref = VecEnv(cfg, num_envs=1, seed=0), VecEnv(cfg, num_envs=1, seed=0, reference=True)
    np.testing.assert_allclose(fast.reset(), ref.reset(), atol=1e-5)
    a = np.zeros((1, 4, 4))
    a[..., 2] = 1
    for _ in range(2):
        o1, r1, *_ = fast.step(a)
        o2, r2, *_ = ref.step(a)
        np.testing.assert_allclose(o1, o2, atol=1e-5)
        assert_bits(r1, r2)
