"""Mirror and rotation symmetry of the readings.

Mirror x -> W - x. Charges are scalars and every dipole (intrinsic or induced)
is a polar vector, so a mirrored scene has the mirrored field, E'(M x) = M E(x),
where M = diag(-1, 1). Mirroring a body mirrors its frame: heading theta ->
pi - theta keeps the EOD's +q ahead and maps the agent dipole (body +x) to its
mirror image; the pellet dipole (pellet +y, i.e. (-sin phi, cos phi)) mirrors to
(sin phi, cos phi), which is pellet orientation -phi. A sensor at angle alpha
from the heading lands at -alpha, and its outward normal n maps to M n, so the
reading E.n = (M E).(M n) is unchanged: readings are permuted, never negated.
The arena [0, W] x [0, H] maps onto itself, so the wall images mirror too.

Symmetry is exact for the model: at tolerance 0 readings agree to 1e-9. At the
default tolerance the fast path culls and interpolates (in float32) and is held
to its accuracy target instead, 1e-6 in normalised units.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest

from efish import Snapshot, sense
from efish.physics import ampullary_angles, knollenorgan_angles, mormyromast_angles

from ..helpers import cfg_with, random_snapshot

RAW = ("mormyromast", "ampullary", "knollenorgan")


def mirror_permutation(angles: np.ndarray) -> np.ndarray:
    """perm[k] = index of the sensor at -angles[k]."""
    target = np.mod(-angles, 2 * np.pi)
    diff = np.abs(np.angle(np.exp(1j * (target[:, None] - angles[None, :]))))
    perm = diff.argmin(axis=1)
    assert np.all(diff[np.arange(len(angles)), perm] < 1e-9), "layout is not mirror symmetric"
    return perm


def test_mirror_permutations_of_the_default_layouts(default_cfg):
    se = default_cfg.sensors
    m = mirror_permutation(mormyromast_angles(se.mormyromast))
    # chin i <-> 9 - i; body sensor k (index 9 + k, angle 30 + k 300/27) <-> 27 - k (index 45 - j)
    np.testing.assert_array_equal(m[:10], np.arange(9, -1, -1))
    np.testing.assert_array_equal(m[10:], 45 - np.arange(10, 36))
    np.testing.assert_array_equal(mirror_permutation(ampullary_angles(se.ampullary)), (-np.arange(24)) % 24)
    np.testing.assert_array_equal(mirror_permutation(knollenorgan_angles(se.knollenorgan)), (-np.arange(12)) % 12)


def mirrored(s: Snapshot) -> Snapshot:
    xy = s.agent_xy.copy()
    xy[:, 0] = s.width - xy[:, 0]
    pxy = s.pellet_xy.copy()
    pxy[:, 0] = s.width - pxy[:, 0]
    return replace(s, agent_xy=xy, agent_heading=np.pi - s.agent_heading, pellet_xy=pxy,
                   pellet_orientation=-s.pellet_orientation)


def rotated(s: Snapshot, beta: float) -> Snapshot:
    c = np.array([s.width / 2, s.height / 2])
    rot = np.array([[np.cos(beta), -np.sin(beta)], [np.sin(beta), np.cos(beta)]])
    return replace(s, agent_xy=(s.agent_xy - c) @ rot.T + c, agent_heading=s.agent_heading + beta,
                   pellet_xy=(s.pellet_xy - c) @ rot.T + c, pellet_orientation=s.pellet_orientation + beta)


def disk_scene(seed: int, n_agents: int, n_pellets: int, size: float = 70.0) -> Snapshot:
    """Random scene inside the disk inscribed in the square arena, so that any rotation stays inside."""
    rng = np.random.default_rng(seed)
    def pts(k):
        r = (size / 2 - 1) * np.sqrt(rng.uniform(0, 1, k))
        a = rng.uniform(0, 2 * np.pi, k)
        return size / 2 + np.column_stack([r * np.cos(a), r * np.sin(a)])
    return Snapshot(agent_xy=pts(n_agents), agent_heading=rng.uniform(-np.pi, np.pi, n_agents),
                    agent_size=rng.uniform(0, 1, n_agents), agent_emitting=rng.random(n_agents) < 0.6,
                    pellet_xy=pts(n_pellets), pellet_orientation=rng.uniform(0, 2 * np.pi, n_pellets),
                    width=size, height=size)


TOLERANCES = [pytest.param(0.0, id="exact"), pytest.param(None, id="default-tolerance")]


def assert_same_readings(a: dict, b: dict, e_min: dict, tolerance: float | None = 0.0) -> None:
    exact = tolerance == 0.0
    for name in RAW:
        np.testing.assert_allclose(b[f"{name}_raw"], a[f"{name}_raw"], rtol=1e-9 if exact else 1e-5,
                                   atol=(1e-6 if exact else 1e-5) * e_min[name], err_msg=name)
        np.testing.assert_allclose(b[name], a[name], rtol=0, atol=1e-9 if exact else 1e-6, err_msg=name)
    np.testing.assert_array_equal(b["knollen_size"], a["knollen_size"])


def ranges(cfg) -> dict:
    se = cfg.sensors
    return {"mormyromast": se.mormyromast.e_min, "ampullary": se.ampullary.e_min, "knollenorgan": se.knollenorgan.threshold}


def permuted(r: dict, cfg) -> dict:
    se = cfg.sensors
    pm, pa, pk = (mirror_permutation(mormyromast_angles(se.mormyromast)),
                  mirror_permutation(ampullary_angles(se.ampullary)),
                  mirror_permutation(knollenorgan_angles(se.knollenorgan)))
    out = dict(r)
    for suffix in ("", "_raw"):
        out["mormyromast" + suffix] = r["mormyromast" + suffix][:, pm]
        out["ampullary" + suffix] = r["ampullary" + suffix][:, pa]
        out["knollenorgan" + suffix] = r["knollenorgan" + suffix][..., pk]
    return out


MIRROR_CASES = [
    pytest.param(("physics.intrinsic=false", "physics.image_order=0"), id="induction-only-free-space"),
    pytest.param(("physics.intrinsic=false",), id="induction-only-walls"),
    pytest.param(("physics.induction=false",), id="intrinsic-only-walls"),
    pytest.param((), id="default"),
    pytest.param(("physics.image_order=3", "sensors.mormyromast.wall_distortion=true"), id="order3-walldist"),
    pytest.param(("physics.image_order=2", "sensors.mormyromast.g_self=0"), id="order2-cons-only"),
]


@pytest.mark.parametrize("tolerance", TOLERANCES)
@pytest.mark.parametrize("overrides", MIRROR_CASES)
@pytest.mark.parametrize("seed", [0, 1, 2])
def test_mirrored_scene_gives_mirrored_readings(overrides, seed, tolerance):
    cfg = cfg_with(*overrides)
    rng = np.random.default_rng(seed)
    s = random_snapshot(rng, 4, 60, width=50.0, height=40.0)
    a = sense(s, cfg, return_raw=True, tolerance=tolerance)
    b = sense(mirrored(s), cfg, return_raw=True, tolerance=tolerance)
    assert any(np.any(a[name] != 0) for name in ("mormyromast", "ampullary"))
    assert_same_readings(permuted(a, cfg), b, ranges(cfg), tolerance)


def test_mirror_test_is_sensitive_to_a_wrongly_mirrored_pellet():
    # negative control: pi - phi (mirroring the pellet frame's x axis) is *not* the mirror of
    # the pellet's dipole; an Ampullary organ next to the pellet tells the difference
    cfg = cfg_with("physics.image_order=0")
    s = Snapshot(agent_xy=[[20, 20]], agent_heading=[0.4], agent_size=[0.5], agent_emitting=[False],
                 pellet_xy=[[22.5, 20.5]], pellet_orientation=[0.3], width=50, height=40)
    good = mirrored(s)
    bad = replace(good, pellet_orientation=np.pi - s.pellet_orientation)
    a = permuted(sense(s, cfg, return_raw=True, tolerance=0), cfg)
    np.testing.assert_allclose(sense(good, cfg, tolerance=0)["ampullary"], a["ampullary"], atol=1e-9)
    assert not np.allclose(sense(bad, cfg)["ampullary"], a["ampullary"], atol=1e-3)


@pytest.mark.parametrize("tolerance", TOLERANCES)
@pytest.mark.parametrize("seed", [0, 1, 2])
@pytest.mark.parametrize("beta", [0.7, np.pi / 2, 2.9, -2.0])
def test_rotated_scene_gives_identical_readings_without_walls(seed, beta, tolerance):
    cfg = cfg_with("physics.image_order=0")
    s = disk_scene(seed, 4, 80)
    a = sense(s, cfg, return_raw=True, tolerance=tolerance)
    b = sense(rotated(s, beta), cfg, return_raw=True, tolerance=tolerance)
    assert np.any(a["mormyromast"] != 0) and np.any(a["ampullary"] != 0)
    assert_same_readings(a, b, ranges(cfg), tolerance)


@pytest.mark.parametrize("tolerance", TOLERANCES)
@pytest.mark.parametrize("order", [1, 2])
def test_quarter_turn_in_a_square_arena_keeps_the_readings_with_walls(order, tolerance):
    cfg = cfg_with(f"physics.image_order={order}", "sensors.mormyromast.wall_distortion=true")
    s = random_snapshot(np.random.default_rng(5), 3, 50, width=40.0, height=40.0)
    a = sense(s, cfg, return_raw=True, tolerance=tolerance)
    b = sense(rotated(s, np.pi / 2), cfg, return_raw=True, tolerance=tolerance)
    assert_same_readings(a, b, ranges(cfg), tolerance)


def test_walls_break_rotation_symmetry():
    # negative control for the test above: a generic angle in a walled arena changes the readings
    cfg = cfg_with("physics.image_order=1", "sensors.mormyromast.wall_distortion=true")
    s = disk_scene(3, 3, 20, size=30.0)
    a = sense(s, cfg, return_raw=True)
    b = sense(rotated(s, 0.7), cfg, return_raw=True)
    assert not np.allclose(a["mormyromast_raw"], b["mormyromast_raw"], rtol=1e-3)


def test_translation_without_walls_keeps_the_readings():
    cfg = cfg_with("physics.image_order=0")
    s = random_snapshot(np.random.default_rng(8), 3, 40, width=60.0, height=60.0)
    moved = replace(s, agent_xy=s.agent_xy + [25.0, 13.0], pellet_xy=s.pellet_xy + [25.0, 13.0],
                    width=100.0, height=100.0)
    assert_same_readings(sense(s, cfg, return_raw=True, tolerance=0), sense(moved, cfg, return_raw=True, tolerance=0),
                         ranges(cfg))


def test_relabelling_agents_permutes_readings_and_slots():
    cfg = cfg_with()
    s = random_snapshot(np.random.default_rng(9), 4, 30, emitting=np.array([True, False, True, True]))
    order = np.array([2, 0, 3, 1])
    t = replace(s, agent_xy=s.agent_xy[order], agent_heading=s.agent_heading[order],
                agent_size=s.agent_size[order], agent_emitting=s.agent_emitting[order])
    a, b = sense(s, cfg, tolerance=0), sense(t, cfg, tolerance=0)
    np.testing.assert_allclose(b["mormyromast"], a["mormyromast"][order], atol=1e-9)
    np.testing.assert_allclose(b["ampullary"], a["ampullary"][order], atol=1e-9)
    n = len(order)
    for new_a, old_a in enumerate(order):
        for new_slot, new_j in enumerate(j for j in range(n) if j != new_a):
            old_j = order[new_j]
            old_slot = old_j if old_j < old_a else old_j - 1
            np.testing.assert_array_equal(b["knollenorgan"][new_a, new_slot], a["knollenorgan"][old_a, old_slot])
            assert b["knollen_size"][new_a, new_slot] == a["knollen_size"][old_a, old_slot]
