"""Where bodies are relative to each other: the one home of nearest-pellet distances.

The foraging shaping reward (``env.tasks.foraging``) and the rollout tables
(``efish.rollout``) both ask "how far is the nearest live pellet, and which is
it"; both call :func:`nearest_pellet`.
"""

from __future__ import annotations

import numpy as np

from .._jit import njit


@njit(cache=True)
def nearest_pellet(xy, pellet_xy, alive, dist, index=None):
    """Distance (cm) from each agent to its nearest live pellet into ``dist`` [B, N]; NaN when none is left.

    ``index`` (int64[B, N], optional) receives the pellet slot, -1 when none is left.
    """
    for b in range(xy.shape[0]):
        for i in range(xy.shape[1]):
            best, best_k = np.inf, -1
            for k in range(pellet_xy.shape[1]):
                if alive[b, k]:
                    d2 = (pellet_xy[b, k, 0] - xy[b, i, 0]) ** 2 + (pellet_xy[b, k, 1] - xy[b, i, 1]) ** 2
                    if d2 < best:
                        best, best_k = d2, k
            dist[b, i] = np.sqrt(best) if best < np.inf else np.nan
            if index is not None:
                index[b, i] = best_k
