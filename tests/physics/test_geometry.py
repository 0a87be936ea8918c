"""Where the sensors sit (docs/model/sensors.md)."""

from __future__ import annotations

import numpy as np
import pytest

from efish.config.schema import AmpullaryConfig, KnollenorganConfig, MormyromastConfig
from efish.physics import ampullary_angles, knollenorgan_angles, mormyromast_angles, sensor_frame


def test_mormyromast_layout():
    a = np.degrees(mormyromast_angles(MormyromastConfig()))
    assert a.shape == (36,)
    np.testing.assert_allclose(a[:10], np.linspace(-30, 30, 10), atol=1e-12)   # the chin, 30 %
    np.testing.assert_allclose(a[10:], 30 + np.arange(1, 27) * 300 / 27, atol=1e-12)
    assert np.all(np.diff(a) > 0)                 # ordered by angle
    assert a[-1] < 330                            # +-30 not repeated: last body sensor short of -30
    wrapped = np.sort(np.mod(a, 360))
    assert len(np.unique(np.round(wrapped, 9))) == 36


def test_mormyromast_body_spacing_is_even_around_the_back():
    a = np.degrees(mormyromast_angles(MormyromastConfig()))
    gaps = np.diff(np.concatenate([a[9:], [a[0] + 360]]))  # from +30 around the back to -30
    np.testing.assert_allclose(gaps, 300 / 27, atol=1e-9)


def test_mormyromast_layout_follows_the_config():
    a = np.degrees(mormyromast_angles(MormyromastConfig(count=12, chin_count=4, chin_half_angle_deg=45)))
    np.testing.assert_allclose(a[:4], [-45, -15, 15, 45], atol=1e-12)
    np.testing.assert_allclose(a[4:], 45 + np.arange(1, 9) * 270 / 9, atol=1e-12)


def test_even_layouts():
    np.testing.assert_allclose(np.degrees(ampullary_angles(AmpullaryConfig())), np.arange(0, 360, 15), atol=1e-12)
    np.testing.assert_allclose(np.degrees(knollenorgan_angles(KnollenorganConfig())), np.arange(0, 360, 30), atol=1e-12)


@pytest.mark.parametrize("heading", [0.0, 0.5, -2.0, np.pi])
def test_sensor_frame_on_the_body_circle_with_outward_normals(heading):
    xy = np.array([3.0, -1.0])
    angles = ampullary_angles(AmpullaryConfig())
    pos, n = sensor_frame(xy, np.array(heading), angles, 1.0)
    assert pos.shape == (24, 2) and n.shape == (24, 2)
    np.testing.assert_allclose(np.linalg.norm(n, axis=1), 1.0)
    np.testing.assert_allclose(pos - xy, n, atol=1e-15)                       # radial, radius 1
    np.testing.assert_allclose(n[0], [np.cos(heading), np.sin(heading)], atol=1e-15)  # sensor 0 ahead
    np.testing.assert_allclose(n[6], [-np.sin(heading), np.cos(heading)], atol=1e-15)  # 90 deg: left side


def test_sensor_frame_broadcasts_over_bodies():
    xy = np.array([[0.0, 0.0], [5.0, 5.0], [1.0, 2.0]])
    heading = np.array([0.0, 1.0, 2.0])
    angles = knollenorgan_angles(KnollenorganConfig())
    pos, n = sensor_frame(xy, heading, angles, 0.5)
    assert pos.shape == (3, 12, 2)
    for i in range(3):
        p1, n1 = sensor_frame(xy[i], heading[i], angles, 0.5)
        np.testing.assert_allclose(pos[i], p1)
        np.testing.assert_allclose(n[i], n1)
