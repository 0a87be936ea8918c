"""Closed-form fields of point sources in SI units (docs/model/physics.md#field-sources), vectorised with numpy.

These are the public, readable versions of the formulas; the numba kernels in
:mod:`efish.physics.kernels` evaluate the same expressions source by source.
Distances are softened, |d|^2 -> |d|^2 + eps^2, so a source on an observation
point gives a finite field.

Two shapes of the same formulas: :func:`monopole_field` and :func:`dipole_field`
sum K sources at M points (the reference and the scenes), while
:func:`pairwise_monopole_field` and :func:`pairwise_dipole_field` give the field
of each source at its own point, broadcast over any leading axes and not summed
(the rollout's measures, which pair bodies with agents across a batch). Both
shapes share the per-source terms below, so they cannot drift apart.

Beside them, the step from a field to the sources it makes: :func:`polarisability`
and :func:`induced_dipole`, the dipole an EOD field induces in a body.
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


def polarisability(radius_m: float | np.ndarray, susceptibility: float, eps0: float = _DEFAULTS.eps0
                   ) -> float | np.ndarray:
    """alpha = chi r^3 / k (C*m per V/m) of a body of radius ``radius_m`` (docs/model/physics.md#induction).

    A body in an EOD field E carries the induced dipole p = alpha E; chi < 0
    (an insulator in water) turns p against E.

    >>> print(f"{polarisability(0.01, -0.5):.4e}")  # an agent of 1 cm radius
    -5.5631e-17
    """
    return radius_m ** 3 * susceptibility / coulomb_constant(eps0)


def induced_dipole(alpha: float | np.ndarray, e_eod: np.ndarray, own: int | None = None) -> np.ndarray:
    """Dipole p = alpha E (C*m, [..., 2]) that one emitter's EOD field E = ``e_eod`` (V/m, [..., 2], at the
    bodies' centres) induces in bodies of polarisability ``alpha`` (C*m per V/m, :func:`polarisability`; a
    scalar or [...], broadcast against the field's leading axes); ``own``, an index along axis -2 of the
    result, is the emitter's own body, which gets none.

    The induction step of the model (docs/model/physics.md#induction), the one place it is written: the
    brute-force oracle (:mod:`efish.physics.reference`), the scenes and the rollout's recorded fields call
    it; the numba kernels (:func:`efish.physics.kernels.induced_dipoles`,
    :func:`efish.rollout.measure_kernels.field_sums`) repeat its product inside their loops over sources and
    are tested against it. Why it is this simple: a body is small beside its distance to the EOD, so the field
    is uniform over it and polarises it into a point dipole at its centre, parallel to the field; bodies are
    insulators in water (chi < 0, so alpha < 0), which turns that dipole against the field. Its field is the
    distortion of the EOD the Mormyromasts read. Only EODs induce, so ``e_eod`` is the field of
    one emitter's monopoles, with their wall images or in free space as the caller's model has it;
    induction is linear, so a body's dipole is the sum of these parts over the emitters, which callers keep
    apart (self and cons) or add up. An emitter's own EOD does not polarise its own body (the model's rule:
    the body is the sensor, and does not read its own polarisation; docs/model/differences.md).

    >>> p = induced_dipole([-2.0, -1.0], np.array([[3.0, 0.0], [0.5, 4.0]]), own=0)
    >>> print(p)  # body 0 emits: nothing induced in it; body 1 takes -1 x its field
    [[ 0.   0. ]
     [-0.5 -4. ]]
    """
    p = np.asarray(alpha, dtype=np.float64)[..., None] * np.asarray(e_eod, dtype=np.float64)
    if own is not None:
        p[..., own, :] = 0.0  # set after the product, so it is +0.0 whatever alpha's sign
    return p


def _as_points(name: str, a: np.ndarray, width: int = 2) -> np.ndarray:
    a = np.asarray(a, dtype=np.float64)
    if a.ndim != 2 or a.shape[1] != width:
        raise ValueError(f"{name} must have shape (n, {width}), got {a.shape}")
    if not np.all(np.isfinite(a)):
        raise ValueError(f"{name} contains NaN or infinite values")
    return a


def _softened_r2(d: np.ndarray, softening: float) -> np.ndarray:
    """|d|^2 + eps^2 over the last axis of displacements ``d`` [..., 2]."""
    return np.einsum("...i,...i->...", d, d) + softening * softening


def _monopole_weight(r2: np.ndarray, charges: np.ndarray) -> np.ndarray:
    """q / |d|^3 (softened) per source: the monopole field is k times this times d."""
    return charges * r2 ** -1.5


def _dipole_terms(d: np.ndarray, r2: np.ndarray, moments: np.ndarray) -> np.ndarray:
    """3 (p.d) d / |d|^5 - p / |d|^3 (softened) per source, [..., 2]: the dipole field is k times this."""
    inv_r3 = r2 ** -1.5
    inv_r5 = inv_r3 / r2
    p_dot_d = np.einsum("...i,...i->...", d, moments)
    return 3.0 * d * (p_dot_d * inv_r5)[..., None] - moments * inv_r3[..., None]


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
    d = points[:, None, :] - positions[None, :, :]                       # (M, K, 2): point - source
    weight = _monopole_weight(_softened_r2(d, softening), charges[None, :])
    return coulomb_constant(eps0) * np.einsum("mki,mk->mi", d, weight)


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
    d = points[:, None, :] - positions[None, :, :]                       # (M, K, 2): point - source
    terms = _dipole_terms(d, _softened_r2(d, softening), moments[None, :, :])
    return coulomb_constant(eps0) * terms.sum(axis=1)


def pairwise_monopole_field(points: np.ndarray, positions: np.ndarray, charges: np.ndarray, *,
                            softening: float = _DEFAULTS.softening_m, eps0: float = _DEFAULTS.eps0) -> np.ndarray:
    """Field k q d / |d|^3 of each charge at its own point, not summed over sources.

    points [..., 2] m, positions [..., 2] m and charges [...] C broadcast
    against each other (numpy rules, the last axis of points and positions
    being x, y) -> [..., 2] V/m, float64. :func:`monopole_field` is the sum of
    this over sources.

    >>> E = pairwise_monopole_field([[0.1, 0.0], [0.0, 0.2]], [0.0, 0.0], 1e-12, softening=0.0)
    >>> print(np.round(E, 6))  # k q / r^2, away from the charge
    [[0.898774 0.      ]
     [0.       0.224694]]
    """
    d = np.asarray(points, dtype=np.float64) - np.asarray(positions, dtype=np.float64)
    weight = _monopole_weight(_softened_r2(d, softening), np.asarray(charges, dtype=np.float64))
    return coulomb_constant(eps0) * (d * weight[..., None])


def pairwise_dipole_field(points: np.ndarray, positions: np.ndarray, moments: np.ndarray, *,
                          softening: float = _DEFAULTS.softening_m, eps0: float = _DEFAULTS.eps0) -> np.ndarray:
    """Field k (3 (p.d) d / |d|^5 - p / |d|^3) of each dipole at its own point, not summed over sources.

    points, positions (m) and moments (C*m) [..., 2] broadcast against each
    other -> [..., 2] V/m, float64. :func:`dipole_field` is the sum of this
    over sources.

    >>> E = pairwise_dipole_field([[0.1, 0.0], [0.0, 0.1]], [0.0, 0.0], [1e-12, 0.0], softening=0.0)
    >>> print(np.round(E, 4))  # on axis p / (2 pi eps0 x^3); broadside half of it, against p
    [[17.9755  0.    ]
     [-8.9877  0.    ]]
    """
    d = np.asarray(points, dtype=np.float64) - np.asarray(positions, dtype=np.float64)
    terms = _dipole_terms(d, _softened_r2(d, softening), np.asarray(moments, dtype=np.float64))
    return coulomb_constant(eps0) * terms
