"""Degenerate and extreme scenes, and bad input at the user-facing boundary.

Every reading must be finite and in [-1, 1]; pytest runs with
filterwarnings=error, so an overflow or invalid-value warning also fails.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from efish import Snapshot, sense
from efish.physics.fast import fast_raw
from efish.physics.reference import reference_raw
from efish.sensors.sense import normalise

from ..helpers import RECEPTORS, assert_valid_readings, cfg_with, plan_for, random_snapshot


def check(snapshot: Snapshot, cfg=None, *, reference_too: bool = True, rng=None) -> dict:
    """Fast path (and reference) readings are valid; with ``reference_too`` they agree at tolerance 0."""
    cfg = cfg or cfg_with()
    r = sense(snapshot, cfg, rng=rng)
    assert_valid_readings(r, snapshot.n_agents)
    if reference_too:
        ref = sense(snapshot, cfg, reference=True, rng=None if rng is None else np.random.default_rng(0))
        assert_valid_readings(ref, snapshot.n_agents)
        exact = sense(snapshot, cfg, tolerance=0.0)
        ref0 = sense(snapshot, cfg, tolerance=0.0, reference=True)
        for name in RECEPTORS:
            np.testing.assert_allclose(exact[name], ref0[name], rtol=0, atol=1e-9, err_msg=name)
    return r


def agents(xy, heading=None, emitting=True, size=0.5, pellets=None, phi=None, w=70.0, h=70.0) -> Snapshot:
    xy = np.asarray(xy, dtype=float)
    n = len(xy)
    return Snapshot(agent_xy=xy, agent_heading=np.zeros(n) if heading is None else heading,
                    agent_size=np.full(n, size), agent_emitting=np.broadcast_to(emitting, (n,)).copy(),
                    pellet_xy=pellets, pellet_orientation=phi, width=w, height=h)


# --------------------------------------------------------------- named hard cases
def test_pellet_centre_on_a_sensor():
    # Ampullary sensor 0 of an agent heading 0 sits at (x + 1, y); put a pellet exactly there with
    # orientation pi/2, so its dipole points along -x: the softened self-field -k p / eps^3 is then
    # along +x, the sensor's normal, ~10 V/m, far above E_max: finite and saturated at +1.
    s = agents([[20, 20], [30, 20]], heading=[0.0, np.pi], pellets=[[21.0, 20.0], [29.0, 20.0]],
               phi=[np.pi / 2, 1.0])
    r = check(s)
    assert r["ampullary"][0, 0] == 1.0
    # Mormyromast 4 (at -3.3 deg, 0.6 mm from the pellet centre) saturates on the induced dipole
    assert np.abs(r["mormyromast"][0, 4]) == 1.0


def test_two_agents_touching():
    r = check(agents([[20, 20], [22, 20]], heading=[0.0, np.pi]))
    assert np.all(np.abs(r["knollenorgan"]) == 1)  # at 2 cm every Knollenorgan fires


def test_agent_in_a_corner():
    # at (1, 1) the body touches both walls and its corner image: images 2 cm away
    for order in range(4):
        cfg = cfg_with(f"physics.image_order={order}", "sensors.mormyromast.wall_distortion=true")
        check(agents([[1, 1], [69, 69]], heading=[np.pi / 4, 0.0]), cfg)
        check(agents([[0, 0], [70, 70]], heading=[1.0, 2.0], pellets=[[0, 70], [70, 0]], phi=[0.0, 3.0]), cfg)


def test_all_agents_at_one_point():
    s = agents([[35, 35]] * 4, heading=[0.0, 1.0, 2.0, 3.0], pellets=[[35, 35], [35, 35]], phi=[0.5, 1.5])
    check(s)
    check(replace(s, agent_heading=np.zeros(4)))  # identical bodies, identical headings
    check(replace(s, agent_emitting=np.array([True, False, True, False])), rng=np.random.default_rng(1))


@pytest.mark.parametrize("size", [10.0, 300.0])
def test_small_and_large_arenas(size):
    rng = np.random.default_rng(int(size))
    for order in (1, 3):
        cfg = cfg_with(f"physics.image_order={order}")
        check(random_snapshot(rng, 4, 30, width=size, height=size), cfg)
    check(random_snapshot(rng, 4, 30, width=size, height=size / 5), cfg_with())


def test_five_thousand_pellets():
    s = random_snapshot(np.random.default_rng(4), 4, 5000, emitting=np.array([True, True, False, True]))
    r = check(s, reference_too=False)
    ref = sense(s, reference=True)
    for name in RECEPTORS:
        np.testing.assert_allclose(r[name], ref[name], rtol=0, atol=1e-6, err_msg=name)


def test_no_emitters():
    s = random_snapshot(np.random.default_rng(5), 4, 50, emitting=np.zeros(4, dtype=bool))
    r = check(s)
    for name in ("mormyromast", "knollenorgan", "knollen_size"):
        assert np.all(r[name] == 0), name
    assert np.any(r["ampullary"] != 0)


def test_every_receptor_off_reads_all_zero():
    cfg = cfg_with("sensors.mormyromast.enabled=false", "sensors.ampullary.enabled=false",
                   "sensors.knollenorgan.enabled=false")
    s = random_snapshot(np.random.default_rng(6), 4, 50, emitting=np.ones(4, dtype=bool))
    for reference in (False, True):
        r = sense(s, cfg, reference=reference, rng=np.random.default_rng(0))
        assert_valid_readings(r, 4)
        for name in RECEPTORS:
            assert np.all(r[name] == 0), name


def test_float32_kernels():
    cfg = cfg_with("physics.dtype=float32")
    rng = np.random.default_rng(7)
    for s in (random_snapshot(rng, 4, 200),
              agents([[1, 1], [1, 1], [3, 1]], pellets=[[2, 1], [1, 1]], phi=[0.0, 0.0]),
              agents([[5, 5], [295, 295]], w=300, h=300)):
        r = check(s, cfg, reference_too=False)
        for name in RECEPTORS:
            assert r[name].dtype == np.float32, name


def test_single_agent():
    r = check(agents([[10, 10]], pellets=[[12, 10]], phi=[0.0]))
    assert r["knollenorgan"].shape == (1, 0, 12) and r["knollen_size"].shape == (1, 0)
    assert np.any(r["mormyromast"] != 0)


def test_empty_pellet_arrays_are_accepted():
    s = Snapshot(agent_xy=[[10, 10]], agent_heading=[0.0], agent_size=[0.5], agent_emitting=[True],
                 pellet_xy=np.zeros((0, 2)), pellet_orientation=np.zeros(0), width=20, height=20)
    assert s.n_pellets == 0
    check(s)


# --------------------------------------------------------------- property-based
def scenes():
    @st.composite
    def build(draw):
        w = draw(st.floats(2.0, 400.0))
        h = draw(st.floats(2.0, 400.0))
        n = draw(st.integers(1, 5))
        p = draw(st.integers(0, 40))
        # coordinates snap to a coarse grid now and then, so coincident bodies and bodies on walls occur
        def coord(limit):
            return st.one_of(st.floats(0.0, limit), st.sampled_from([0.0, limit, limit / 2, min(1.0, limit)]))
        axy = [[draw(coord(w)), draw(coord(h))] for _ in range(n)]
        pxy = [[draw(coord(w)), draw(coord(h))] for _ in range(p)]
        angle = st.floats(-10.0, 10.0)
        return Snapshot(agent_xy=axy, agent_heading=[draw(angle) for _ in range(n)],
                        agent_size=[draw(st.floats(0.0, 1.0)) for _ in range(n)],
                        agent_emitting=[draw(st.booleans()) for _ in range(n)],
                        pellet_xy=np.reshape(pxy, (-1, 2)), pellet_orientation=[draw(angle) for _ in range(p)],
                        width=w, height=h)
    return build()


@settings(max_examples=40, deadline=None, database=None, suppress_health_check=[HealthCheck.too_slow])
@given(s=scenes(), order=st.integers(0, 3), walldist=st.booleans(), seed=st.integers(0, 2**32 - 1))
def test_random_scenes_give_valid_readings_and_match_the_reference(s, order, walldist, seed):
    cfg = cfg_with(f"physics.image_order={order}", f"sensors.mormyromast.wall_distortion={str(walldist).lower()}")
    r = sense(s, cfg, rng=np.random.default_rng(seed))
    assert_valid_readings(r, s.n_agents)
    plan = plan_for(cfg, s, tolerance=0.0)
    batch = s.as_batch()
    got = normalise(fast_raw(batch, plan), batch.agent_size, plan)
    ref = normalise(reference_raw(batch, plan), batch.agent_size, plan)
    assert_valid_readings({k: v[0] for k, v in ref.items()}, s.n_agents)
    for name in ("mormyromast", "ampullary"):
        np.testing.assert_allclose(got[name], ref[name], rtol=0, atol=1e-9, err_msg=name)


# --------------------------------------------------------------- bad input
GOOD = dict(agent_xy=[[10.0, 10.0], [20.0, 20.0]], agent_heading=[0.0, 1.0], agent_size=[0.5, 0.5],
            agent_emitting=[True, False], pellet_xy=[[15.0, 15.0]], pellet_orientation=[0.0], width=70.0, height=70.0)


@pytest.mark.parametrize("field, value", [
    ("agent_xy", [10.0, 10.0]),                      # not (n, 2)
    ("agent_xy", [[10.0, 10.0, 0.0], [1.0, 2.0, 0.0]]),
    ("agent_xy", np.zeros((0, 2))),                  # nobody
    ("agent_xy", [[np.nan, 10.0], [20.0, 20.0]]),
    ("agent_xy", [[np.inf, 10.0], [20.0, 20.0]]),
    ("agent_xy", [[-1.0, 10.0], [20.0, 20.0]]),      # outside the arena
    ("agent_xy", [[10.0, 10.0], [20.0, 71.0]]),
    ("agent_heading", [0.0]),
    ("agent_heading", [0.0, np.nan]),
    ("agent_size", [0.5, -0.1]),
    ("agent_size", [0.5, 1.5]),
    ("agent_size", [[0.5, 0.5]]),
    ("agent_emitting", [True]),
    ("pellet_xy", [[15.0, np.nan]]),
    ("pellet_xy", [[15.0, 15.0, 1.0]]),
    ("pellet_xy", [[75.0, 15.0]]),
    ("pellet_orientation", [0.0, 1.0]),
    ("pellet_orientation", [np.inf]),
    ("width", 0.0),
    ("width", -5.0),
    ("width", np.nan),
    ("height", 0.0),
    ("height", np.inf),
])
def test_bad_snapshot_input_names_the_field(field, value):
    with pytest.raises(ValueError, match=field):
        Snapshot(**{**GOOD, field: value})


def test_good_snapshot_input_is_accepted():
    s = Snapshot(**GOOD)
    assert s.n_agents == 2 and s.n_pellets == 1
    assert s.agent_xy.dtype == np.float64 and s.agent_emitting.dtype == bool


def test_pellets_default_to_none():
    s = Snapshot(agent_xy=[[1.0, 1.0]], agent_heading=[0.0], agent_size=[0.0], agent_emitting=[False])
    assert s.n_pellets == 0 and s.width == 70.0
