"""Far-field interpolation: exactness on trigonometric polynomials and the error model."""

from __future__ import annotations

import numpy as np
import pytest

from efish.config import compose
from efish.config.schema import ConfigError, MormyromastConfig
from efish.physics import build_plan
from efish.physics.far_field import trig_interpolation_matrix
from efish.physics.fields import coulomb_constant, dipole_field
from efish.physics.geometry import even_angles, mormyromast_angles


@pytest.mark.parametrize("q", [3, 5, 9, 21])
def test_interpolation_is_exact_for_trig_polynomials_up_to_degree(q):
    rng = np.random.default_rng(q)
    degree = (q - 1) // 2
    coef = rng.normal(size=(2, degree + 1))

    def f(t):
        m = np.arange(degree + 1)[None, :]
        return (coef[0] * np.cos(m * t[:, None]) + coef[1] * np.sin(m * t[:, None])).sum(axis=1)

    targets = rng.uniform(0, 2 * np.pi, 50)
    w = trig_interpolation_matrix(targets, q)
    np.testing.assert_allclose(w @ f(even_angles(q)), f(targets), atol=1e-12)


def test_interpolation_needs_odd_point_count():
    with pytest.raises(ValueError, match="odd"):
        trig_interpolation_matrix(np.zeros(3), 4)


@pytest.mark.parametrize("q", [3, 7, 13, 21])
def test_single_dipole_error_is_within_the_model_bound(q):
    """The safety factor C=100 of the config must cover the measured interpolation error."""
    r, k, c_safety = 0.01, coulomb_constant(), compose().physics.far_field_safety
    targets = mormyromast_angles(MormyromastConfig())
    w = trig_interpolation_matrix(targets, q)
    rng = np.random.default_rng(0)
    for dist in (0.03, 0.06, 0.12, 0.3):
        for _ in range(20):
            a, phi = rng.uniform(0, 2 * np.pi, 2)
            pos = np.array([[dist * np.cos(a), dist * np.sin(a)]])
            moment = 1e-13 * np.array([[np.cos(phi), np.sin(phi)]])

            def reading(t, pos=pos, moment=moment):
                u = np.stack([np.cos(t), np.sin(t)], axis=1)
                return np.einsum("si,si->s", dipole_field(r * u, pos, moment), u)

            err = np.abs(w @ reading(even_angles(q)) - reading(targets)).max()
            bound = 2 * k * 1e-13 / (dist - r) ** 3
            assert err <= c_safety * q * bound * (r / dist) ** ((q + 1) // 2) + 1e-12 * bound


def test_far_field_is_off_at_tolerance_zero_and_on_by_default():
    cfg = compose()
    assert not build_plan(cfg, tolerance=0).on("far_field")
    assert build_plan(cfg).on("far_field")
    assert not build_plan(compose(["physics.far_field_levels=[]"])).on("far_field")


def test_even_level_is_rejected():
    with pytest.raises(ConfigError, match="far_field_levels"):
        compose(["physics.far_field_levels=[3,4]"])
