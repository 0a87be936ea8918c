"""Inequality and dominance measures (docs/methods/analyses.md#analysis-behaviour)."""

from __future__ import annotations

import numpy as np


def theil_t(x: np.ndarray) -> float:
    """Theil T index of non-negative shares: mean of (x/mu) ln(x/mu), with 0 ln 0 = 0.

    Every agent counts, including one that got nothing; 0 for a group that got nothing.

    >>> theil_t(np.array([1.0, 1.0, 1.0])), round(theil_t(np.array([0.0, 0.0, 3.0])), 6)
    (0.0, 1.098612)
    """
    x = np.asarray(x, dtype=np.float64)
    if x.size == 0 or np.any(x < 0):
        raise ValueError("theil_t needs a non-empty array of non-negative values")
    mu = x.mean()
    if mu == 0:
        return 0.0
    r = x / mu
    with np.errstate(divide="ignore", invalid="ignore"):
        terms = np.where(r > 0, r * np.log(r), 0.0)
    return float(terms.mean())


def win_ratio(given: np.ndarray, received: np.ndarray) -> np.ndarray:
    """given / (given + received); NaN where an agent neither gave nor received."""
    given, received = np.asarray(given, dtype=np.float64), np.asarray(received, dtype=np.float64)
    total = given + received
    with np.errstate(divide="ignore", invalid="ignore"):
        return np.where(total > 0, given / total, np.nan)
