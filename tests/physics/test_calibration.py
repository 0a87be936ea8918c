"""Detection ranges of the receptor classes (docs/model/sensors.md#calibration-checks, supplement of the paper).

A target sits on the observer's heading axis in a 400 x 400 cm arena with no
wall images (physics.image_order=0) and no noise (rng=None). The documented ranges
are Mormyromast prey 5 cm / agent 10 cm, Ampullary prey 4 cm / agent 8 cm,
Knollenorgan agent 100 cm. "Inside" is 90 % of the documented range; "clearly
outside" is twice the range.

Measured with this model (scan in 0.01 cm steps, 0.05 cm for Knollenorgans;
last distance with any non-zero reading): Mormyromast prey 6.8 cm, agent
13.1 cm; Ampullary prey 4.35 cm (pellet dipole across the axis, the weakest
orientation) to 5.6 cm (along the axis), agent 11.0 cm; Knollenorgan 100.9 cm for
an emitter whose EOD axis points at the listener (79.25 cm broadside).
The passive and active ranges come out 10-40 % beyond the supplement's round
numbers (the supplement's figures are estimates at the E_min thresholds), so
2x the documented range is a margin of >= 1.4x over every measured edge, while
0.9x the range is inside every measured edge.
"""

from __future__ import annotations

import itertools

import numpy as np
import pytest

from efish import Snapshot, sense

from ..helpers import cfg_with

ARENA = 400.0
OBSERVER = (100.0, 200.0)
PELLET_ORIENTATIONS = [0.0, np.pi / 4, np.pi / 2, 2.0, np.pi]  # pellet dipole across .. along the axis


@pytest.fixture(scope="module")
def cfg():
    return cfg_with("physics.image_order=0")


def pellet_ahead(d: float, phi: float, emitting: bool) -> Snapshot:
    x, y = OBSERVER
    return Snapshot(agent_xy=[[x, y]], agent_heading=[0.0], agent_size=[0.5], agent_emitting=[emitting],
                    pellet_xy=[[x + d, y]], pellet_orientation=[phi], width=ARENA, height=ARENA)


def agent_ahead(d: float, observer_emits: bool, target_emits: bool, target_heading: float = 0.0) -> Snapshot:
    x, y = OBSERVER
    return Snapshot(agent_xy=[[x, y], [x + d, y]], agent_heading=[0.0, target_heading], agent_size=[0.5, 0.8],
                    agent_emitting=[observer_emits, target_emits], width=ARENA, height=ARENA)


def observer_reads(r: dict, name: str) -> np.ndarray:
    return r[name][0]


@pytest.mark.parametrize("reference", [False, True], ids=["fast", "reference"])
def test_mormyromast_detects_prey_within_5_cm(cfg, reference):
    for phi in PELLET_ORIENTATIONS:
        near = sense(pellet_ahead(4.5, phi, emitting=True), cfg, reference=reference)
        far = sense(pellet_ahead(10.0, phi, emitting=True), cfg, reference=reference)
        assert np.any(observer_reads(near, "mormyromast") != 0), phi
        assert np.all(observer_reads(far, "mormyromast") == 0), phi
    # a silent fish senses no prey with its Mormyromasts (nothing polarises the pellet)
    silent = sense(pellet_ahead(4.5, 0.0, emitting=False), cfg, reference=reference)
    assert np.all(observer_reads(silent, "mormyromast") == 0)


@pytest.mark.parametrize("reference", [False, True], ids=["fast", "reference"])
def test_mormyromast_detects_a_silent_agent_within_10_cm(cfg, reference):
    for heading in (0.0, np.pi / 2, np.pi):  # induction of a round body does not depend on its heading
        near = sense(agent_ahead(9.0, True, False, heading), cfg, reference=reference)
        far = sense(agent_ahead(20.0, True, False, heading), cfg, reference=reference)
        assert np.any(observer_reads(near, "mormyromast") != 0)
        assert np.all(observer_reads(far, "mormyromast") == 0)


@pytest.mark.parametrize("reference", [False, True], ids=["fast", "reference"])
def test_ampullary_detects_prey_within_4_cm(cfg, reference):
    for phi in PELLET_ORIENTATIONS:
        near = sense(pellet_ahead(3.6, phi, emitting=False), cfg, reference=reference)
        far = sense(pellet_ahead(8.0, phi, emitting=False), cfg, reference=reference)
        assert np.any(observer_reads(near, "ampullary") != 0), phi
        assert np.all(observer_reads(far, "ampullary") == 0), phi


@pytest.mark.parametrize("reference", [False, True], ids=["fast", "reference"])
def test_ampullary_detects_a_silent_agent_within_8_cm(cfg, reference):
    for heading in (0.0, np.pi / 2, np.pi, 4.0):
        near = sense(agent_ahead(7.2, False, False, heading), cfg, reference=reference)
        far = sense(agent_ahead(16.0, False, False, heading), cfg, reference=reference)
        assert np.any(observer_reads(near, "ampullary") != 0), heading
        assert np.all(observer_reads(far, "ampullary") == 0), heading


def test_ampullary_alone_reads_nothing_in_free_space(cfg):
    # the own intrinsic field is removed (docs/model/sensors.md#ampullary-organs); with no walls and nobody else,
    # all zero
    r = sense(pellet_ahead(200.0, 0.0, emitting=True), cfg)
    assert np.all(observer_reads(r, "ampullary") == 0)


@pytest.mark.parametrize("reference", [False, True], ids=["fast", "reference"])
def test_knollenorgan_hears_an_emitting_agent_within_100_cm(cfg, reference):
    # the 100 cm range is for an emitter whose EOD axis points at the listener (heading 0 or pi)
    for heading in (0.0, np.pi):
        near = sense(agent_ahead(90.0, False, True, heading), cfg, reference=reference)
        far = sense(agent_ahead(200.0, False, True, heading), cfg, reference=reference)
        assert np.any(near["knollenorgan"][0, 0] != 0), heading
        assert near["knollen_size"][0, 0] == pytest.approx(0.5 + 0.5 * 0.8)
        assert np.all(far["knollenorgan"][0, 0] == 0), heading
        assert far["knollen_size"][0, 0] == 0.0
    # a silent conspecific is never heard, however close
    quiet = sense(agent_ahead(3.0, True, False), cfg, reference=reference)
    assert np.all(quiet["knollenorgan"][0] == 0) and quiet["knollen_size"][0, 0] == 0.0


def test_knollenorgan_range_broadside_is_shorter_by_the_cube_root_of_two(cfg):
    # broadside a dipole's field is half its on-axis field: range 100 / 2^(1/3) ~ 80 cm
    # (measured edges: 100.9 cm on axis, 79.25 cm broadside)
    assert np.any(sense(agent_ahead(70.0, False, True, np.pi / 2), cfg)["knollenorgan"][0, 0] != 0)
    assert np.all(sense(agent_ahead(90.0, False, True, np.pi / 2), cfg)["knollenorgan"][0, 0] == 0)


def test_knollenorgan_ignores_the_own_eod(cfg):
    # the observer emits, the other agent does not: the other agent hears it, the observer hears nobody
    r = sense(agent_ahead(30.0, True, False), cfg)
    assert np.all(r["knollenorgan"][0] == 0)
    assert np.any(r["knollenorgan"][1] != 0)
    assert r["knollen_size"][1, 0] == pytest.approx(0.5 + 0.5 * 0.5)


def test_detection_fades_monotonically_with_distance(cfg):
    # the strongest Mormyromast reading falls as the prey moves away along the axis (single
    # sensors need not: the zero line of the induced dipole's field sweeps over the body)
    peaks = [float(np.abs(observer_reads(sense(pellet_ahead(d, 0.0, True), cfg), "mormyromast")).max())
             for d in np.arange(1.5, 9.0, 0.25)]
    assert peaks[0] > 0.5 and peaks[-1] == 0
    assert all(a > b or a == b == 0 for a, b in itertools.pairwise(peaks)), peaks


def test_front_sensors_read_prey_ahead_the_strongest(cfg):
    from efish.physics import mormyromast_angles
    r = sense(pellet_ahead(3.0, 0.0, True), cfg)
    m = np.abs(observer_reads(r, "mormyromast"))
    angles = np.degrees(mormyromast_angles(cfg.sensors.mormyromast))
    strongest = angles[np.argmax(m)]
    assert abs(strongest) < 10.0  # the chin sensors nearest the heading axis
