"""The unit conversion and the angle convention that every layer shares, written once.

Positions are centimetres in the config, the environment and the tables, and
metres in the field formulas (:mod:`efish.physics.fields`); angles are radians
in [-pi, pi). Pure numpy and on the ground floor (layer 0), so that the layers
that read tables (``efish.analysis``, ``efish.figures``) use the same
conversion and the same wrap as the simulator without loading numba.
"""

from __future__ import annotations

import numpy as np

CM = 0.01  # m per cm


def wrap(a: np.ndarray) -> np.ndarray:
    """Angles ``a`` (rad) wrapped to [-pi, pi), as float64.

    >>> float(wrap(3 * np.pi / 2)), float(wrap(np.pi))
    (-1.5707963267948966, -3.141592653589793)
    """
    return (np.asarray(a, dtype=np.float64) + np.pi) % (2 * np.pi) - np.pi
