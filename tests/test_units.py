"""The unit conversion and the angle convention every layer shares (efish.units)."""

from __future__ import annotations

import numpy as np
import pytest

from efish.units import CM, wrap


def test_cm_is_a_hundredth_of_a_metre():
    assert CM == 0.01 and 150 * CM == pytest.approx(1.5)


@pytest.mark.parametrize(("angle", "wrapped"), [(0.0, 0.0), (np.pi / 2, np.pi / 2), (3 * np.pi / 2, -np.pi / 2),
                                                (-3 * np.pi / 2, np.pi / 2), (np.pi, -np.pi), (-np.pi, -np.pi),
                                                (7 * np.pi, -np.pi), (2 * np.pi + 0.25, 0.25)])
def test_wrap_maps_angles_to_minus_pi_up_to_pi(angle, wrapped):
    assert float(wrap(angle)) == pytest.approx(wrapped, abs=1e-12)


def test_wrap_keeps_the_direction_and_takes_any_array():
    a = np.random.default_rng(0).uniform(-50, 50, (4, 5))
    w = wrap(a)
    assert w.shape == a.shape and w.dtype == np.float64 and np.all((w >= -np.pi) & (w < np.pi))
    np.testing.assert_allclose(np.exp(1j * w), np.exp(1j * a), atol=1e-12)
    assert wrap([1, 2]).dtype == np.float64  # ints and lists too (tables hold int columns)
