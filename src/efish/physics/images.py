"""Method of images for an insulating rectangular arena [0, W] x [0, H] (docs/model/physics.md#walls-and-images).

An image is indexed by how many times, and in which direction, it was mirrored
along x (``ix``) and y (``iy``). Along one axis of length L the image of x with
index i sits at ``i*L + x`` for even i and ``(i+1)*L - x`` for odd i (i = 1 is
the mirror in the wall at L, i = -1 the mirror in the wall at 0, and so on).
Order n keeps every image with |ix| + |iy| <= n: order 1 is one mirror per
wall, the model's first-order method (docs/model/physics.md#walls-and-images).
Monopole images keep their sign; a dipole image is the mirrored vector (the
component normal to each mirroring wall flips once per mirror). Every mirror
scales the source by ``scale``.
"""

from __future__ import annotations

import numpy as np


def image_indices(order: int) -> np.ndarray:
    """All (ix, iy) with |ix| + |iy| <= order, the identity (0, 0) first. Shape (I, 2), int64.

    >>> image_indices(1).tolist()
    [[0, 0], [-1, 0], [0, -1], [0, 1], [1, 0]]
    """
    if not 0 <= order <= 3:
        raise ValueError(f"image order must be in 0..3, got {order}")
    rng = range(-order, order + 1)
    rest = [(ix, iy) for ix in rng for iy in rng if 0 < abs(ix) + abs(iy) <= order]
    return np.array([(0, 0)] + rest, dtype=np.int64).reshape(-1, 2)


def image_weights(indices: np.ndarray, scale: float) -> np.ndarray:
    """scale ** (number of mirrors) for each image; the identity has weight 1."""
    return scale ** np.abs(indices).sum(axis=1).astype(np.float64)


def image_coordinate(x: np.ndarray, i: np.ndarray, length: np.ndarray) -> np.ndarray:
    """Coordinate of the i-th image of x along an axis of the given length."""
    odd = (i % 2) != 0
    return np.where(odd, (i + 1) * length - x, i * length + x)


def image_sources(xy: np.ndarray, vec: np.ndarray | None, width: float, height: float,
                  indices: np.ndarray, scale: float) -> tuple[np.ndarray, np.ndarray | None, np.ndarray]:
    """Images of sources at ``xy`` (K, 2) with optional vectors ``vec`` (K, 2).

    Returns positions (I*K, 2), mirrored and scaled vectors (I*K, 2) or None, and
    the weights (I*K,) to multiply scalar strengths (charges) with. Image-major
    order: the first K rows are the sources themselves.
    """
    ix, iy = indices[:, 0][:, None], indices[:, 1][:, None]
    px = image_coordinate(xy[None, :, 0], ix, width)
    py = image_coordinate(xy[None, :, 1], iy, height)
    pos = np.stack([px, py], axis=-1).reshape(-1, 2)
    w = np.repeat(image_weights(indices, scale), xy.shape[0])
    if vec is None:
        return pos, None, w
    sx = np.where(ix % 2 != 0, -1.0, 1.0)
    sy = np.where(iy % 2 != 0, -1.0, 1.0)
    mirrored = np.stack([sx * vec[None, :, 0], sy * vec[None, :, 1]], axis=-1).reshape(-1, 2)
    return pos, mirrored * w[:, None], w
