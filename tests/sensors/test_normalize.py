"""Log normalisation, Knollenorgan binarisation and the size channel (docs/model/sensors.md#normalisation,
docs/model/sensors.md#knollenorgans)."""

from __future__ import annotations

import numpy as np
import pytest

from efish.sensors import binarize, knollen_size_channel, log_normalize

RANGES = [(5e-8, 5e-2), (2e-10, 2e-8), (1.0, 10.0)]


@pytest.mark.parametrize("e_min, e_max", RANGES)
def test_exact_values_at_the_ends_and_the_geometric_midpoint(e_min, e_max):
    mid = np.sqrt(e_min * e_max)
    y = log_normalize(np.array([e_min, e_max, mid, -e_min, -e_max, -mid]), e_min, e_max)
    assert y[0] == 0.0 and y[3] == 0.0
    assert y[1] == 1.0 and y[4] == -1.0
    assert y[2] == pytest.approx(0.5, abs=1e-12) and y[5] == pytest.approx(-0.5, abs=1e-12)


def test_one_decade_steps_in_the_mormyromast_range():
    # 6 decades: every decade above E_min adds 1/6
    s = 5e-8 * 10.0 ** np.arange(7)
    np.testing.assert_allclose(log_normalize(s, 5e-8, 5e-2), np.arange(7) / 6, atol=1e-12)


@pytest.mark.parametrize("e_min, e_max", RANGES)
def test_odd_symmetry(e_min, e_max):
    s = np.geomspace(e_min / 100, e_max * 100, 201)
    np.testing.assert_array_equal(log_normalize(-s, e_min, e_max), -log_normalize(s, e_min, e_max))


@pytest.mark.parametrize("e_min, e_max", RANGES)
def test_at_or_below_e_min_reads_exactly_zero(e_min, e_max):
    s = np.array([0.0, -0.0, e_min, -e_min, e_min * (1 - 1e-12), e_min / 1e6, -e_min / 3, 1e-300])
    y = log_normalize(s, e_min, e_max)
    assert np.all(y == 0.0)
    assert log_normalize(np.array([e_min * (1 + 1e-9)]), e_min, e_max)[0] > 0


@pytest.mark.parametrize("e_min, e_max", RANGES)
def test_saturates_at_plus_minus_one(e_min, e_max):
    y = log_normalize(np.array([e_max * 1.0001, 1e300, -e_max * 10, np.inf, -np.inf]), e_min, e_max)
    np.testing.assert_array_equal(y, [1.0, 1.0, -1.0, 1.0, -1.0])


@pytest.mark.parametrize("e_min, e_max", RANGES)
def test_monotone_and_bounded(e_min, e_max):
    s = np.concatenate([-np.geomspace(e_max * 1e3, e_min * 1e-3, 500), [0.0], np.geomspace(e_min * 1e-3, e_max * 1e3, 500)])
    y = log_normalize(s, e_min, e_max)
    assert np.all(np.diff(y) >= 0)
    assert np.all(np.abs(y) <= 1)
    inside = (np.abs(s) > e_min) & (np.abs(s) < e_max)
    assert np.all(np.diff(y[inside][s[inside] > 0]) > 0)  # strictly increasing inside the range


def test_dtype_and_shape_are_kept():
    s = np.full((2, 3, 4), 5e-5)
    assert log_normalize(s, 5e-8, 5e-2).shape == (2, 3, 4)
    y32 = log_normalize(s.astype(np.float32), 5e-8, 5e-2)
    assert y32.dtype == np.float32
    assert y32[0, 0, 0] == pytest.approx(0.5, abs=1e-6)
    # float32 readings at or below e_min read exactly 0 (the largest float32 not above 5e-8)
    below = np.float32(5e-8)
    if float(below) > 5e-8:
        below = np.nextafter(below, np.float32(0))
    assert float(below) <= 5e-8
    assert log_normalize(np.array([below, -below], dtype=np.float32), 5e-8, 5e-2).tolist() == [0.0, 0.0]
    assert log_normalize(np.array([1, -2, 0]), 1.0, 10.0).dtype == np.float64


@pytest.mark.parametrize("e_min, e_max", [(0.0, 1.0), (-1.0, 1.0), (1.0, 1.0), (2.0, 1.0)])
def test_bad_range_is_rejected(e_min, e_max):
    with pytest.raises(ValueError, match="e_min"):
        log_normalize(np.array([1.0]), e_min, e_max)


def test_binarize_threshold_is_strict():
    thr = 2e-7
    s = np.array([3e-7, -3e-7, 2e-7, -2e-7, 1e-7, 0.0, 1.0, -1.0])
    np.testing.assert_array_equal(binarize(s, thr), [1, -1, 0, 0, 0, 0, 1, -1])
    assert binarize(s.astype(np.float32), thr).dtype == np.float32


def test_size_channel():
    spikes = np.array([[[0, 0, 1], [0, 0, 0], [-1, 0, 0]]], dtype=float)   # (1 agent, 3 slots, 3 sensors)
    sizes = np.array([[0.0, 0.7, 1.0]])
    # heard -> 0.5 + 0.5 s (so a heard size-0 fish reads 0.5, not 0); not heard -> 0
    np.testing.assert_allclose(knollen_size_channel(spikes, sizes), [[0.5, 0.0, 1.0]])
