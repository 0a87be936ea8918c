"""Ray-casting perception baseline (docs/model/sensors.md#ray-casting, this project's definition).

Rays leave the agent centre at the Mormyromast angles; each returns the
proximity 1 - d / L of the first thing it hits within L (0 if nothing) and
the kind of thing: none 0, food 1/3, agent 2/3, wall 1.
"""

from __future__ import annotations

import numpy as np

from .._jit import njit

KIND_NONE, KIND_FOOD, KIND_AGENT, KIND_WALL = 0.0, 1.0 / 3.0, 2.0 / 3.0, 1.0


@njit(cache=True)
def ray_circle(ox, oy, ux, uy, cx, cy, radius):
    """Distance along the unit ray (ox, oy) + t (ux, uy) to a circle, inf if missed (0 if inside)."""
    dx, dy = cx - ox, cy - oy
    t = dx * ux + dy * uy
    perp2 = dx * dx + dy * dy - t * t
    if perp2 > radius * radius:
        return np.inf
    half = np.sqrt(radius * radius - perp2)
    if t + half < 0:
        return np.inf
    return max(t - half, 0.0)


@njit(cache=True)
def ray_wall(ox, oy, ux, uy, width, height):
    """Distance along the ray to the arena boundary."""
    tx = (width - ox) / ux if ux > 0 else (-ox / ux if ux < 0 else np.inf)
    ty = (height - oy) / uy if uy > 0 else (-oy / uy if uy < 0 else np.inf)
    return min(tx, ty)


@njit(cache=True)
def cast_rays(xy, heading, pellet_xy, alive, width, height, angles, length, agent_r, pellet_r, prox, kind):
    """prox, kind: float[B, N, R] for rays at ``angles`` (rad from the heading)."""
    b_count, n = xy.shape[0], xy.shape[1]
    for b in range(b_count):
        for i in range(n):
            ox, oy = xy[b, i, 0], xy[b, i, 1]
            for r in range(angles.shape[0]):
                ux, uy = np.cos(heading[b, i] + angles[r]), np.sin(heading[b, i] + angles[r])
                best, what = ray_wall(ox, oy, ux, uy, width[b], height[b]), KIND_WALL
                for k in range(pellet_xy.shape[1]):
                    if alive[b, k]:
                        d = ray_circle(ox, oy, ux, uy, pellet_xy[b, k, 0], pellet_xy[b, k, 1], pellet_r)
                        if d < best:
                            best, what = d, KIND_FOOD
                for j in range(n):
                    if j != i:
                        d = ray_circle(ox, oy, ux, uy, xy[b, j, 0], xy[b, j, 1], agent_r)
                        if d < best:
                            best, what = d, KIND_AGENT
                if best <= length:
                    prox[b, i, r], kind[b, i, r] = 1.0 - best / length, what
                else:
                    prox[b, i, r], kind[b, i, r] = 0.0, KIND_NONE
