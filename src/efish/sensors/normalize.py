"""From raw field readings (V/m) to observations in [-1, 1] (docs/model/sensors.md#normalisation,
docs/model/sensors.md#knollenorgans)."""

from __future__ import annotations

import numpy as np


def log_normalize(s: np.ndarray, e_min: float, e_max: float) -> np.ndarray:
    """Signed log compression of raw readings into [-1, 1].

    m = clip(|s|, e_min, e_max); y = sign(s) * (log10 m - log10 e_min) / (log10 e_max - log10 e_min).
    Readings at or below ``e_min`` give exactly 0, readings at or above ``e_max`` give +-1.

    >>> log_normalize(np.array([5e-8, -5e-2, 5e-5, 0.0]), 5e-8, 5e-2)
    array([ 0. , -1. ,  0.5,  0. ])
    """
    if not 0 < e_min < e_max:
        raise ValueError(f"log_normalize needs 0 < e_min < e_max, got e_min={e_min}, e_max={e_max}")
    s = np.asarray(s)
    # Normalise in float64 whatever the input: in float32, e_min itself rounds, and
    # log10(m) - log10(e_min) would leave tiny non-zero values below the threshold.
    s64 = s.astype(np.float64, copy=False)
    m = np.clip(np.abs(s64), e_min, e_max)
    y = np.sign(s64) * (np.log10(m) - np.log10(e_min)) / (np.log10(e_max) - np.log10(e_min))
    return y.astype(s.dtype if np.issubdtype(s.dtype, np.floating) else np.float64, copy=False)


def binarize(s: np.ndarray, threshold: float) -> np.ndarray:
    """sign(s) where |s| > threshold, else 0 (Knollenorgan spikes)."""
    s = np.asarray(s)
    return np.where(np.abs(s) > threshold, np.sign(s), 0.0).astype(s.dtype, copy=False)


def knollen_size_channel(spikes: np.ndarray, sizes: np.ndarray) -> np.ndarray:
    """0.5 + 0.5 * size of the conspecific in a slot when any of its sensors spiked, else 0.

    ``spikes`` (..., slots, sensors), ``sizes`` (..., slots) -> (..., slots).
    """
    heard = np.any(spikes != 0, axis=-1)
    return np.where(heard, 0.5 + 0.5 * sizes, 0.0).astype(spikes.dtype, copy=False)
