"""Method of images for the insulating rectangular arena (docs/model/physics.md#walls-and-images)."""

from __future__ import annotations

import numpy as np
import pytest

from efish.physics import dipole_field, image_indices, image_sources, monopole_field

W, H = 0.7, 0.5  # m


def wall_points(wall: str, n: int = 25) -> tuple[np.ndarray, np.ndarray]:
    """Points along a wall (excluding corners) and the wall's unit normal."""
    t = np.linspace(0.02, 0.98, n)
    if wall == "left":
        return np.column_stack([np.zeros(n), t * H]), np.array([1.0, 0.0])
    if wall == "right":
        return np.column_stack([np.full(n, W), t * H]), np.array([1.0, 0.0])
    if wall == "bottom":
        return np.column_stack([t * W, np.zeros(n)]), np.array([0.0, 1.0])
    return np.column_stack([t * W, np.full(n, H)]), np.array([0.0, 1.0])


WALL_INDEX = {"left": (-1, 0), "right": (1, 0), "bottom": (0, -1), "top": (0, 1)}


def single_wall(wall: str) -> np.ndarray:
    """The source itself and its one image in ``wall``."""
    return np.array([(0, 0), WALL_INDEX[wall]], dtype=np.int64)


@pytest.mark.parametrize("order, count", [(0, 1), (1, 5), (2, 13), (3, 25)])
def test_image_indices(order, count):
    idx = image_indices(order)
    assert idx.shape == (count, 2) and idx.dtype == np.int64
    assert idx[0].tolist() == [0, 0]
    assert np.all(np.abs(idx).sum(axis=1) <= order)
    assert len({tuple(r) for r in idx.tolist()}) == count  # no duplicates


@pytest.mark.parametrize("order", [-1, 4])
def test_image_order_out_of_range(order):
    with pytest.raises(ValueError, match="order"):
        image_indices(order)


def test_image_positions_vectors_and_weights():
    xy = np.array([[0.1, 0.2]])
    vec = np.array([[3.0, 5.0]])
    idx = np.array([(0, 0), (-1, 0), (1, 0), (0, -1), (0, 1), (1, 1), (2, 0), (-2, -1)], dtype=np.int64)
    pos, mom, w = image_sources(xy, vec, W, H, idx, 0.9)
    np.testing.assert_allclose(pos, [
        [0.1, 0.2],               # the source
        [-0.1, 0.2],              # mirror in x = 0
        [2 * W - 0.1, 0.2],       # mirror in x = W
        [0.1, -0.2],              # mirror in y = 0
        [0.1, 2 * H - 0.2],       # mirror in y = H
        [2 * W - 0.1, 2 * H - 0.2],
        [2 * W + 0.1, 0.2],       # two mirrors along x: a translation by 2 W
        [-2 * W + 0.1, -0.2],
    ], atol=1e-15)
    np.testing.assert_allclose(w, 0.9 ** np.array([0, 1, 1, 1, 1, 2, 2, 3]))
    # a mirror flips the component normal to the wall; two mirrors along one axis restore it
    signs = np.array([[1, 1], [-1, 1], [-1, 1], [1, -1], [1, -1], [-1, -1], [1, 1], [1, -1]])
    np.testing.assert_allclose(mom, signs * vec * w[:, None])
    # scalars (charges) keep their sign: only the weights are returned for them
    pos2, none, w2 = image_sources(xy, None, W, H, idx, 0.9)
    assert none is None
    np.testing.assert_array_equal(pos2, pos)
    assert np.all(w2 > 0)


def test_image_sources_are_image_major():
    xy = np.array([[0.1, 0.2], [0.3, 0.4], [0.5, 0.1]])
    idx = image_indices(1)
    pos, _, w = image_sources(xy, None, W, H, idx, 0.95)
    assert pos.shape == (15, 2)
    np.testing.assert_array_equal(pos[:3], xy)
    for i, (ix, iy) in enumerate(idx):
        one, _, _ = image_sources(xy, None, W, H, np.array([(ix, iy)]), 0.95)
        np.testing.assert_allclose(pos[3 * i:3 * i + 3], one)
        assert np.all(w[3 * i:3 * i + 3] == 0.95 ** (abs(ix) + abs(iy)))


@pytest.mark.parametrize("wall", ["left", "right", "bottom", "top"])
def test_monopole_and_its_image_give_zero_normal_field_on_the_wall(wall):
    xy = np.array([[0.23, 0.11]])
    pos, _, w = image_sources(xy, None, W, H, single_wall(wall), 1.0)
    pts, normal = wall_points(wall)
    e = monopole_field(pts, pos, 1e-15 * w, softening=0.0)
    e_alone = monopole_field(pts, xy, [1e-15], softening=0.0)
    scale = np.abs(e_alone @ normal).max()
    assert scale > 0
    assert np.abs(e @ normal).max() <= 1e-12 * scale
    # the tangential field is doubled, not cancelled
    tangent = normal[::-1]
    np.testing.assert_allclose(e @ tangent, 2 * (e_alone @ tangent), rtol=1e-12, atol=1e-12 * scale)


@pytest.mark.parametrize("wall", ["left", "right", "bottom", "top"])
@pytest.mark.parametrize("angle", [0.0, 0.4, np.pi / 2, 2.5, 4.0])
def test_dipole_and_its_mirrored_image_satisfy_the_insulating_boundary_condition(wall, angle):
    xy = np.array([[0.31, 0.07]])
    vec = 1e-20 * np.array([[np.cos(angle), np.sin(angle)]])
    pos, mom, _ = image_sources(xy, vec, W, H, single_wall(wall), 1.0)
    pts, normal = wall_points(wall)
    e = dipole_field(pts, pos, mom, softening=0.0)
    scale = np.abs(dipole_field(pts, xy, vec, softening=0.0)).max()
    assert np.abs(e @ normal).max() <= 1e-12 * scale


def test_a_copied_dipole_vector_would_violate_the_boundary_condition():
    # the decision of docs/model/differences.md (mirror, not copy) matters: a copied normal component leaves E.n != 0
    xy = np.array([[0.31, 0.07]])
    vec = 1e-20 * np.array([[1.0, 0.0]])
    pos, _, _ = image_sources(xy, vec, W, H, single_wall("left"), 1.0)
    pts, normal = wall_points("left")
    e = dipole_field(pts, pos, np.vstack([vec, vec]), softening=0.0)
    assert np.abs(e @ normal).max() > 1e-3 * np.abs(dipole_field(pts, xy, vec, softening=0.0)).max()


def test_scaled_images_leave_a_small_normal_field():
    # on the wall the image's normal field is exactly minus the source's: with scale 0.95, 5 % remains
    xy = np.array([[0.23, 0.11]])
    pos, _, w = image_sources(xy, None, W, H, single_wall("bottom"), 0.95)
    pts, normal = wall_points("bottom")
    e_n = monopole_field(pts, pos, 1e-15 * w, softening=0.0) @ normal
    alone = monopole_field(pts, xy, [1e-15], softening=0.0) @ normal
    np.testing.assert_allclose(e_n, 0.05 * alone, rtol=1e-10)


@pytest.mark.parametrize("order", [1, 2, 3])
def test_image_set_is_mirror_symmetric(order):
    # the set of images of the mirrored source (x -> W - x) is the mirrored set of images
    xy = np.array([[0.13, 0.31]])
    vec = np.array([[0.6, -0.8]])
    idx = image_indices(order)
    pos, mom, _ = image_sources(xy, vec, W, H, idx, 0.95)
    pos_m, mom_m, _ = image_sources(np.array([[W - 0.13, 0.31]]), np.array([[-0.6, -0.8]]), W, H, idx, 0.95)
    a = {tuple(np.round(np.r_[W - p[0], p[1], -m[0], m[1]], 12)) for p, m in zip(pos, mom, strict=True)}
    b = {tuple(np.round(np.r_[p, m], 12)) for p, m in zip(pos_m, mom_m, strict=True)}
    assert a == b
