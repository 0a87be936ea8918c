"""Closed-form fields of point sources in SI units (docs/model/physics.md#field-sources), vectorised with numpy.

These are the public, readable versions of the formulas; the numba kernels in
:mod:`efish.physics.kernels` evaluate the same expressions source by source.
Distances are softened, |d|^2 -> |d|^2 + eps^2, so a source on an observation
point gives a finite field.
"""

from __future__ import annotations

import numpy as np

from ..config.schema import PhysicsConfig

# The keyword defaults below are PhysicsConfig's (eps0, softening_m): the schema is their one home. Simulation
# code passes the configured values.
_DEFAULTS = PhysicsConfig()


def coulomb_constant(eps0: float = _DEFAULTS.eps0) -> float:
    """k = 1 / (4 pi eps0), in V*m/C."""
    return 1.0 / (4.0 * np.pi * eps0)


def _as_points(name: str, a: np.ndarray, width: int = 2) -> np.ndarray:
    a = np.asarray(a, dtype=np.float64)
    if a.ndim != 2 or a.shape[1] != width:
        raise ValueError(f"{name} must have shape (n, {width}), got {a.shape}")
    if not np.all(np.isfinite(a)):
        raise ValueError(f"{name} contains NaN or infinite values")
    return a


def _displacements(points: np.ndarray, positions: np.ndarray, softening: float
                   ) -> tuple[np.ndarray, np.ndarray]:
    """d = point - source (M, K, 2) and the softened squared distance (M, K)."""
    d = points[:, None, :] - positions[None, :, :]
    r2 = np.einsum("mki,mki->mk", d, d) + softening * softening
    return d, r2


def monopole_field(points: np.ndarray, positions: np.ndarray, charges: np.ndarray, *,
                   softening: float = _DEFAULTS.softening_m, eps0: float = _DEFAULTS.eps0) -> np.ndarray:
    """Field of point charges, E = sum_k k q_k d / |d|^3, at ``points``.

    points (M, 2) m, positions (K, 2) m, charges (K,) C -> (M, 2) V/m, float64.

    >>> E = monopole_field([[0.1, 0.0]], [[0.0, 0.0]], [1e-12], softening=0.0)
    >>> print(f"{E[0, 0]:.6f}")  # k q / x^2
    0.898774
    """
    points = _as_points("points", points)
    positions = _as_points("positions", positions)
    charges = np.asarray(charges, dtype=np.float64)
    if charges.shape != (positions.shape[0],):
        raise ValueError(f"charges must have shape ({positions.shape[0]},), got {charges.shape}")
    d, r2 = _displacements(points, positions, softening)
    inv_r3 = r2 ** -1.5
    return coulomb_constant(eps0) * np.einsum("mki,mk->mi", d, charges[None, :] * inv_r3)


def dipole_field(points: np.ndarray, positions: np.ndarray, moments: np.ndarray, *,
                 softening: float = _DEFAULTS.softening_m, eps0: float = _DEFAULTS.eps0) -> np.ndarray:
    """Field of point dipoles, E = k (3 (p.d) d / |d|^5 - p / |d|^3), at ``points``.

    points (M, 2) m, positions (K, 2) m, moments (K, 2) C*m -> (M, 2) V/m, float64.

    >>> E = dipole_field([[0.1, 0.0]], [[0.0, 0.0]], [[1e-12, 0.0]], softening=0.0)
    >>> print(f"{E[0, 0]:.4f}")  # on axis: p / (2 pi eps0 x^3)
    17.9755
    """
    points = _as_points("points", points)
    positions = _as_points("positions", positions)
    moments = _as_points("moments", moments)
    if moments.shape[0] != positions.shape[0]:
        raise ValueError(f"moments must have shape ({positions.shape[0]}, 2), got {moments.shape}")
    d, r2 = _displacements(points, positions, softening)
    inv_r3 = r2 ** -1.5
    inv_r5 = inv_r3 / r2
    p_dot_d = np.einsum("mki,ki->mk", d, moments)
    e = 3.0 * d * (p_dot_d * inv_r5)[..., None] - moments[None, :, :] * inv_r3[..., None]
    return coulomb_constant(eps0) * e.sum(axis=1)
