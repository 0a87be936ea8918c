"""The numba fast path against the brute-force reference (every source, no culling).

Random scenes: 1-6 agents, 0-200 pellets, random emitters, 70 x 70 cm arena.
The reference is computed once per (config, seed) and reused for every
tolerance and dtype of the fast path.
"""

from __future__ import annotations

import functools

import numpy as np
import pytest

from efish.physics.fast import fast_raw
from efish.physics.reference import reference_raw
from efish.sensors.sense import normalise

from ..helpers import cfg_with, plan_for, random_snapshot

RAW = ("mormyromast", "ampullary", "knollenorgan")
NORM = ("mormyromast", "ampullary", "knollenorgan", "knollen_size")


def scene(seed: int):
    rng = np.random.default_rng(seed)
    return random_snapshot(rng, int(rng.integers(1, 7)), int(rng.integers(0, 201)))


@functools.lru_cache(maxsize=None)
def reference(overrides: tuple[str, ...], seed: int):
    cfg = cfg_with(*overrides)
    snap = scene(seed)
    plan = plan_for(cfg, snap, tolerance=0.0)
    raw = reference_raw(snap.as_batch(), plan)
    return snap, raw, normalise(raw, snap.as_batch().agent_size, plan)


def fast(overrides: tuple[str, ...], seed: int, tolerance=None, dtype=None):
    cfg = cfg_with(*overrides)
    snap = scene(seed)
    plan = plan_for(cfg, snap, tolerance=tolerance, dtype=dtype)
    raw = fast_raw(snap.as_batch(), plan)
    return raw, normalise(raw, snap.as_batch().agent_size, plan)


def e_min(overrides, name):
    se = cfg_with(*overrides).sensors
    return {"mormyromast": se.mormyromast.e_min, "ampullary": se.ampullary.e_min,
            "knollenorgan": se.knollenorgan.threshold}[name]


def max_norm_diff(a: dict, b: dict, name: str) -> float:
    return float(np.max(np.abs(a[name].astype(np.float64) - b[name].astype(np.float64)), initial=0.0))


def test_the_random_scenes_exercise_every_receptor():
    # guard against a vacuous comparison: the scenes must produce non-zero readings of every class
    seen = {name: False for name in NORM}
    for seed in range(6):
        _, _, norm = reference((), seed)
        for name in NORM:
            seen[name] |= bool(np.any(norm[name] != 0))
    assert all(seen.values()), seen


@pytest.mark.parametrize("seed", range(8))
def test_default_tolerance_matches_reference(seed):
    snap, _, ref = reference((), seed)
    _, got = fast((), seed)
    for name in ("mormyromast", "ampullary"):
        assert max_norm_diff(got, ref, name) <= 1e-6, name
    # spikes and the size channel are discontinuous: they must agree exactly
    np.testing.assert_array_equal(got["knollenorgan"], ref["knollenorgan"])
    np.testing.assert_array_equal(got["knollen_size"], ref["knollen_size"])


@pytest.mark.parametrize("seed", [0, 1])
def test_patchy_benchmark_scenes_match_reference_at_default_and_zero_tolerance(seed):
    """Clustered scenes (food patches, agents foraging beside pellets) fill the far-field
    buckets up to the sparsely used highest ones, and the exact bucket."""
    from efish.bench.scenes import benchmark_batch
    from efish.physics.plan import build_plan

    cfg = cfg_with()
    batch = benchmark_batch(cfg, 4, seed)
    exact_plan = build_plan(cfg, tolerance=0.0)
    ref_raw = reference_raw(batch, exact_plan)
    ref = normalise(ref_raw, batch.agent_size, exact_plan)
    got = normalise(fast_raw(batch, build_plan(cfg)), batch.agent_size, build_plan(cfg))
    for name in ("mormyromast", "ampullary"):
        assert np.any(ref[name] != 0), name  # not a vacuous comparison
        assert max_norm_diff(got, ref, name) <= 1e-6, name
    exact_raw = fast_raw(batch, exact_plan)
    for name in ("mormyromast", "ampullary"):
        np.testing.assert_allclose(getattr(exact_raw, name), getattr(ref_raw, name), rtol=1e-9,
                                   atol=1e-6 * e_min((), name), err_msg=name)


GATES = [(1, 1), (1, 0), (0, 1)]


def variant(order: int, wall: bool, gates: tuple[int, int]) -> tuple[str, ...]:
    return (f"physics.image_order={order}", f"sensors.mormyromast.wall_distortion={str(wall).lower()}",
            f"sensors.mormyromast.g_self={gates[0]}", f"sensors.mormyromast.g_cons={gates[1]}")


VARIANTS = [pytest.param(variant(o, w, g), id=f"order{o}-walldist{int(w)}-gates{g[0]}{g[1]}")
            for o in range(4) for w in (False, True) for g in GATES]


@pytest.mark.parametrize("overrides", VARIANTS)
@pytest.mark.parametrize("seed", [10, 11])
def test_tolerance_zero_agrees_to_round_off(overrides, seed):
    _, ref_raw, ref = reference(overrides, seed)
    raw, got = fast(overrides, seed, tolerance=0.0)
    for name in NORM:
        assert max_norm_diff(got, ref, name) <= 1e-12, name
    for name in RAW:
        # relative 1e-9 per reading; the absolute floor (1e-6 E_min) only covers readings that
        # cancel to almost nothing, a million times below what normalisation can see
        np.testing.assert_allclose(getattr(raw, name), getattr(ref_raw, name), rtol=1e-9,
                                   atol=1e-6 * e_min(overrides, name), err_msg=name)


def test_the_reference_follows_a_configured_eps0():
    """The reference's closed-form fields take physics.eps0 from the plan, as the kernels take k."""
    overrides = ("physics.eps0=1.2e-11",)
    _, ref_raw, _ = reference(overrides, 10)
    raw, _ = fast(overrides, 10, tolerance=0.0)
    _, default_raw, _ = reference((), 10)
    assert not np.allclose(ref_raw.ampullary, default_raw.ampullary)
    for name in RAW:
        np.testing.assert_allclose(getattr(raw, name), getattr(ref_raw, name), rtol=1e-9,
                                   atol=1e-6 * e_min(overrides, name), err_msg=name)


# float32. Positions are metres in float32, so a body 1 mm from a sensor is placed to ~3e-8 m,
# i.e. ~3e-5 of the distance, ~1e-4 after the d^-3; readings are sums of many such terms whose
# near and far parts (and the two terms of E.n of one dipole) cancel, which multiplies that
# error. Measured over 40 random scenes (seeds 20-59, the configs below): raw error at most
# 7.1e-4 of the largest reading of the same agent and array, normalised error at most 8.3e-4
# (seed 41: a pellet 1.2 mm from a Mormyromast, a 1.2 % raw error; seed 59: a reading near
# E_min left by cancelling larger terms). The bounds below keep a ~2.5x margin. A float32
# regression that loses relative precision on a whole term (e.g. forming the cons moment as
# total - self) shows up as errors of 1e-2 to 0.3 and fails them.
F32_NORM = 2e-3
F32_RAW_OF_MAX = 2e-3


@pytest.mark.parametrize("overrides", [(), variant(0, False, (1, 1)), variant(3, True, (1, 1)),
                                       variant(2, False, (0, 1)), variant(1, True, (1, 0))],
                         ids=["default", "order0", "order3-walldist", "cons-only", "self-only-walldist"])
@pytest.mark.parametrize("tolerance", [0.0, None], ids=["tol0", "default-tol"])
@pytest.mark.parametrize("seed", [20, 41, 59])
def test_float32_agrees_within_its_precision(overrides, tolerance, seed):
    _, ref_raw, ref = reference(overrides, seed)
    raw, got = fast(overrides, seed, tolerance=tolerance, dtype="float32")
    for name in RAW:
        assert getattr(raw, name).dtype == np.float32, name
    if tolerance == 0.0:  # culling may zero whole arrays that read below E_min: compare raw without it
        for name in ("mormyromast", "ampullary"):
            r = getattr(ref_raw, name)
            scale = np.max(np.abs(r), axis=-1, keepdims=True) if r.size else r
            err = np.abs(getattr(raw, name).astype(np.float64) - r)
            assert np.all(err <= F32_RAW_OF_MAX * scale + 1e-6 * e_min(overrides, name)), name
    for name in ("mormyromast", "ampullary"):
        assert got[name].dtype == np.float32
        assert max_norm_diff(got, ref, name) <= F32_NORM, name


def test_float32_knollenorgan_spikes_match_away_from_the_threshold():
    for seed in (20, 41, 59):
        _, ref_raw, ref = reference((), seed)
        _, got = fast((), seed, dtype="float32")
        thr = e_min((), "knollenorgan")
        clear = np.abs(np.abs(ref_raw.knollenorgan) - thr) > 1e-3 * thr  # not within float32 reach of the threshold
        np.testing.assert_array_equal(got["knollenorgan"][clear], ref["knollenorgan"][clear])


# ------------------------------------------------------------------------- gates
@pytest.fixture(scope="module")
def gate_scene():
    """Three agents near pellets, agent 0 and 1 emit, agent 2 is silent."""
    from efish import Snapshot
    return Snapshot(agent_xy=[[20, 20], [26, 21], [22, 26]], agent_heading=[0.3, 2.5, -1.2],
                    agent_size=[0.2, 0.6, 0.9], agent_emitting=[True, True, False],
                    pellet_xy=[[23, 20], [21, 23], [25, 25], [50, 50]], pellet_orientation=[0.1, 1.0, 2.0, 3.0],
                    width=70, height=70)


def gate_raw(snap, *overrides):
    cfg = cfg_with(*overrides)
    return reference_raw(snap.as_batch(), plan_for(cfg, snap, tolerance=0.0))


def test_self_only_reading_is_exactly_the_self_part(gate_scene):
    raw = gate_raw(gate_scene, "sensors.mormyromast.g_cons=0")
    assert np.any(raw.morm_self != 0) and np.any(raw.morm_cons != 0)
    np.testing.assert_array_equal(raw.mormyromast, raw.morm_self)


def test_cons_only_reading_is_k_cons_times_the_cons_part(gate_scene):
    raw = gate_raw(gate_scene, "sensors.mormyromast.g_self=0")
    k_cons = cfg_with().sensors.mormyromast.k_cons
    assert k_cons == 100.0
    np.testing.assert_array_equal(raw.mormyromast, k_cons * raw.morm_cons)


def test_control_gain_is_100_only_for_silent_agents(gate_scene):
    raw = gate_raw(gate_scene)
    np.testing.assert_array_equal(raw.mormyromast[0, :2], raw.morm_self[0, :2] + raw.morm_cons[0, :2])
    np.testing.assert_array_equal(raw.mormyromast[0, 2], raw.morm_self[0, 2] + 100.0 * raw.morm_cons[0, 2])


def test_silent_agent_has_no_self_part(gate_scene):
    for overrides in [(), ("sensors.mormyromast.wall_distortion=true",), ("physics.image_order=3",)]:
        raw = gate_raw(gate_scene, *overrides)
        assert np.all(raw.morm_self[0, 2] == 0.0)
        assert np.all(raw.morm_self[0, :2] != 0.0)  # emitters do see their own images
        assert np.all(raw.morm_cons[0, 2] != 0.0)


def test_self_and_cons_parts_add_up_to_the_induced_field_of_all_emitters(gate_scene):
    # induction is linear: muting agent 1 leaves agent 0's self part unchanged and removes
    # agent 1's share from everybody's cons part
    from dataclasses import replace
    both = gate_raw(gate_scene)
    muted = gate_raw(replace(gate_scene, agent_emitting=np.array([True, False, False])))
    np.testing.assert_allclose(muted.morm_self[0, 0], both.morm_self[0, 0], rtol=1e-12)
    assert np.all(muted.morm_cons[0, 0] == 0.0)  # the only other emitter is muted
    assert not np.allclose(muted.morm_cons[0, 2], both.morm_cons[0, 2])


LARGE_SCENES = [pytest.param(("arena.width_cm=560", "arena.height_cm=560"), id="560x560"),
                pytest.param(("arena.width_cm=280", "arena.height_cm=280", "env.n_agents=8", "env.obs_agents=8"),
                             id="280x280-8agents"),
                pytest.param(("arena.food_multiplier=10",), id="70x70-crowded-x10")]


@functools.lru_cache(maxsize=None)
def large_scene(overrides: tuple[str, ...]):
    """Two patchy snapshots (one as at reset, one foraging) of a large or crowded arena and their reference."""
    from efish.bench.scenes import benchmark_batch
    from efish.physics.plan import build_plan

    cfg = cfg_with(*overrides)
    batch = benchmark_batch(cfg, 2, 3)
    exact_plan = build_plan(cfg, tolerance=0.0)
    ref_raw = reference_raw(batch, exact_plan)
    return cfg, batch, ref_raw, normalise(ref_raw, batch.agent_size, exact_plan)


@pytest.mark.parametrize("overrides", LARGE_SCENES)
def test_large_and_crowded_scenes_match_reference(overrides):
    """Thousands of pellets (560 x 560: about 5,500, x5 with their images) or ten times the food of 70 x 70:
    tolerance 0 equals the reference to rounding, the default tolerance stays within 1e-6."""
    from efish.physics.plan import build_plan

    cfg, batch, ref_raw, ref = large_scene(overrides)
    assert batch.pellet_alive.sum(axis=1).min() >= 500  # really a crowded scene
    exact_raw = fast_raw(batch, build_plan(cfg, tolerance=0.0))
    for name in ("mormyromast", "ampullary"):
        assert np.any(ref[name] != 0), name  # not a vacuous comparison
        np.testing.assert_allclose(getattr(exact_raw, name), getattr(ref_raw, name), rtol=1e-9,
                                   atol=1e-6 * e_min((), name), err_msg=name)
    plan = build_plan(cfg)
    got = normalise(fast_raw(batch, plan), batch.agent_size, plan)
    for name in ("mormyromast", "ampullary"):
        assert max_norm_diff(got, ref, name) <= 1e-6, name
    np.testing.assert_array_equal(got["knollenorgan"], ref["knollenorgan"])
