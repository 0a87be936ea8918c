"""The numba kernels of the per-step measures (efish.rollout.measures) against their numpy twins
(efish.rollout.measures_reference), on random states of real envs: same keys, shapes and dtypes; counts, chosen
bodies and NaN/-inf where they are, exactly; every float to 1e-10 relative."""

from __future__ import annotations

import numpy as np
import pytest

from efish.config import compose
from efish.env.vec_env import VecEnv
from efish.rollout import measures, measures_reference
from efish.units import wrap

ENVS = {
    "four": ["arena=patchy70"],
    "lone": ["env.n_agents=1"],
    "pair": ["env.n_agents=2", "arena=onepatch"],
    "homing": ["env=homing", "arena=uniform70"],
    # every constant log_fields reads off the plan and the physics config, away from its default: a kernel that
    # used its own numbers would part from the reference here
    "other_physics": ["arena=patchy70", "physics.eps0=1e-11", "physics.eod_charge_c=2e-15",
                      "physics.eod_half_separation_cm=0.3", "physics.pellet_radius_cm=0.4",
                      "physics.agent_dipole_coulomb_metre=3e-23", "physics.pellet_dipole_coulomb_metre=5e-24",
                      "physics.susceptibility=-0.3", "physics.softening_m=2e-3"],
}
SEEDS = range(4)
SELECTIONS = ("size_agent1", "size_agent2")  # copied from the chosen agent: exact, or the wrong one was chosen


@pytest.fixture(scope="module", params=sorted(ENVS))
def env(request):
    """Three arenas of an env of ``ENVS``, reset."""
    env = VecEnv(compose(ENVS[request.param]), num_envs=3, seed=3)
    env.reset()
    return env


def randomise(env: VecEnv, seed: int) -> None:
    """Agents anywhere in their arena, some pellets within 5 cm of an agent, about a third of them dead, and in
    the last arena none alive (no food: NaN bearings, and with one agent a field of exactly 0)."""
    s, rng = env.state, np.random.default_rng(seed)
    b, n, p = *s.heading.shape, s.alive.shape[1]
    size = np.stack([s.width, s.height], -1)[:, None, :]                       # [B, 1, 2] cm
    s.xy[:] = rng.uniform(0.0, 1.0, (b, n, 2)) * size
    s.heading[:] = rng.uniform(-np.pi, np.pi, (b, n))
    s.size[:] = rng.uniform(0.0, 1.0, (b, n))                                  # distinct: they identify agents
    s.pellet_xy[:] = rng.uniform(0.0, 1.0, (b, p, 2)) * size
    close = rng.uniform(0.0, 1.0, (b, p)) < 0.5
    near = s.xy[np.arange(b)[:, None], rng.integers(0, n, (b, p))] + rng.uniform(-5.0, 5.0, (b, p, 2))
    s.pellet_xy[close] = near[close]
    s.pellet_phi[:] = rng.uniform(-np.pi, np.pi, (b, p))
    s.alive[:] = rng.uniform(0.0, 1.0, (b, p)) < 0.7
    s.alive[-1] = False


def assert_same(fast: dict[str, np.ndarray], ref: dict[str, np.ndarray], shape: tuple[int, int]) -> None:
    assert list(fast) == list(ref)
    for key, a in fast.items():
        r = ref[key]
        assert (a.shape, a.dtype) == (shape, r.dtype), key
        if a.dtype.kind in "iub" or key in SELECTIONS:
            np.testing.assert_array_equal(a, r, err_msg=key)
            continue
        np.testing.assert_array_equal(np.isnan(a), np.isnan(r), err_msg=key)
        np.testing.assert_array_equal(np.isinf(a), np.isinf(r), err_msg=key)
        np.testing.assert_array_equal(a[np.isinf(a)], r[np.isinf(r)], err_msg=key)
        ok = np.isfinite(a)
        if "bearing" in key:  # pi and -pi are one direction: compare on the circle
            assert np.all(np.abs(wrap(a[ok] - r[ok])) <= 1e-10 * np.pi), key
        elif key.startswith("log_"):  # relative on |E| itself
            np.testing.assert_allclose(10.0 ** a[ok], 10.0 ** r[ok], rtol=1e-10, atol=0.0, err_msg=key)
        else:
            np.testing.assert_allclose(a[ok], r[ok], rtol=1e-10, atol=0.0, err_msg=key)


@pytest.mark.parametrize("seed", SEEDS)
def test_nearest_matches_the_reference(env, seed):
    randomise(env, seed)
    assert_same(measures.nearest(env), measures_reference.nearest_reference(env), env.state.heading.shape)


@pytest.mark.parametrize("seed", SEEDS)
def test_food_counts_match_the_reference(env, seed):
    randomise(env, seed)
    fast = measures.food_counts(env)
    assert_same(fast, measures_reference.food_counts_reference(env), env.state.heading.shape)
    assert fast["food_count_5cm"][:-1].any(), "the state should put pellets within 5 cm"


@pytest.mark.parametrize("seed", SEEDS)
@pytest.mark.parametrize("range_cm", [20.0, 100.0])
def test_agents_in_range_match_the_reference(env, seed, range_cm):
    randomise(env, seed)
    assert_same({"n": measures.agents_in_range(env, range_cm)},
                {"n": measures_reference.agents_in_range_reference(env, range_cm)}, env.state.heading.shape)


@pytest.mark.parametrize("seed", SEEDS)
def test_log_fields_match_the_reference(env, seed):
    randomise(env, seed)
    fast = measures.log_fields(env)
    assert_same(fast, measures_reference.log_fields_reference(env), env.state.heading.shape)
    if env.n == 1:  # the last arena holds no other body: the field is exactly 0
        assert np.all(fast["log_amp_field"][-1] == -np.inf) and np.all(fast["log_morm_field"][-1] == -np.inf)


@pytest.fixture
def tied():
    """One arena, 70 x 70 cm, of four agents: 1, 2 and 3 exactly 5 cm from agent 0, which sits at the centre
    (equally far from all four walls); two live pellets exactly 3 cm from agent 0, and a third on agent 3's
    bisector between front and left (bearing pi/4, half-way between two sectors)."""
    env = VecEnv(compose(["arena=patchy70"]), num_envs=1, seed=0)
    env.reset()
    s = env.state
    s.xy[0] = [[35.0, 35.0], [40.0, 35.0], [30.0, 35.0], [35.0, 40.0]]
    s.heading[0] = [0.0, 1.0, 2.0, 0.0]
    s.size[0] = [0.1, 0.2, 0.3, 0.4]
    s.alive[:] = False
    s.pellet_xy[0, :3] = [[35.0, 32.0], [38.0, 35.0], [37.0, 42.0]]
    s.alive[0, :3] = True
    return env


def test_ties_go_to_the_lower_index_as_in_the_stable_sort(tied):
    fast = measures.nearest(tied)
    assert_same(fast, measures_reference.nearest_reference(tied), (1, 4))
    assert fast["size_agent1"][0, 0] == 0.2 and fast["size_agent2"][0, 0] == 0.3   # agents 1, then 2
    assert fast["bearing_agent_rad"][0, 0] == 0.0 and fast["dist_agent2_cm"][0, 0] == 5.0
    assert fast["bearing_wall_rad"][0, 0] == wrap(np.pi)                          # the x = 0 wall, first of four
    assert fast["bearing_food_rad"][0, 0] == wrap(-np.pi / 2)                     # pellet slot 0, first of two
    assert_same(measures.food_counts(tied), measures_reference.food_counts_reference(tied), (1, 4))
