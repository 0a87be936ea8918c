"""Raw receptor readings: the one result type of the fast path and the reference oracle."""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

if TYPE_CHECKING:
    from .plan import EffectPlan


@dataclass
class RawReadings:
    """Raw field readings E.n in V/m, before noise and normalisation.

    mormyromast: float[B, N, 36]
    ampullary: float[B, N, 24]
    knollenorgan: float[B, N, N-1, 12]  # slot j = j-th other agent in id order
    morm_self, morm_cons: float[B, N, 36] or None  # ungated parts (reference only)
    error_bound: float64[B, N, 2] or None  # fast path with physics.error_bound: bound of |reading - exact| of every Mormyromast
        # (column 0) and Ampullary (1) reading of an agent, V/m (0 at tolerance 0: exact to round-off)
    """

    mormyromast: np.ndarray
    ampullary: np.ndarray
    knollenorgan: np.ndarray
    morm_self: np.ndarray | None = None
    morm_cons: np.ndarray | None = None
    error_bound: np.ndarray | None = None


def normalised_error_bound(raw: RawReadings, plan: EffectPlan) -> np.ndarray:
    """float64[B, N, 2]: bound of the error of every normalised Mormyromast (0) and Ampullary (1) reading.

    The normalisation (docs/model/sensors.md#normalisation) after a noise factor u is Lipschitz in the raw reading
    with constant u / (E_min ln 10 (log10 E_max - log10 E_min)): it is flat below E_min
    and above E_max, logarithmic between. So a raw error bound times that constant, at the
    largest factor noise can draw, bounds the normalised error with or without noise.
    """
    if raw.error_bound is None:
        raise ValueError("these readings carry no error bound: the fast path reports one with "
                         "physics.error_bound=true (the reference is exact)")

    def lipschitz(lo: float, hi: float, noise: float) -> float:
        return noise / (lo * np.log(10) * np.log10(hi / lo))

    scale = np.array([lipschitz(*plan.morm_range, plan.max_noise), lipschitz(*plan.amp_range, plan.max_amp_noise)])
    return raw.error_bound * scale


def empty_readings(b: int, n: int, plan: EffectPlan, dtype=np.float64) -> RawReadings:
    """All-zero raw readings of the right shapes."""
    return RawReadings(
        mormyromast=np.zeros((b, n, len(plan.morm_angles)), dtype),
        ampullary=np.zeros((b, n, len(plan.amp_angles)), dtype),
        knollenorgan=np.zeros((b, n, n - 1, len(plan.knollen_angles)), dtype))
