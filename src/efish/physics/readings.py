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
    """

    mormyromast: np.ndarray
    ampullary: np.ndarray
    knollenorgan: np.ndarray
    morm_self: np.ndarray | None = None
    morm_cons: np.ndarray | None = None


def empty_readings(b: int, n: int, plan: EffectPlan, dtype=np.float64) -> RawReadings:
    """All-zero raw readings of the right shapes."""
    return RawReadings(
        mormyromast=np.zeros((b, n, len(plan.morm_angles)), dtype),
        ampullary=np.zeros((b, n, len(plan.amp_angles)), dtype),
        knollenorgan=np.zeros((b, n, n - 1, len(plan.knollen_angles)), dtype))
