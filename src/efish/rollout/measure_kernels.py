"""Numba kernels of the per-step measures (:mod:`efish.rollout.measures`): one pass over arena, agent and body.

The numpy formulas (:mod:`efish.rollout.measures_reference`) build
[B, N, N + P, 2] arrays and sort them at every step of an assay, which cost
several times the simulation itself; these loops write straight into
preallocated [B, N] outputs. They are the reference's formulas with its tie
rules (the lowest index wins a tie, as a stable sort puts it first), so
distances, choices, counts and NaN/-inf come out as the reference's; the
fields differ by rounding only (k taken out of the sums, |d|^-3 from a square
root, sums vectorised). ``tests/rollout/test_measure_kernels.py`` holds them
to the reference. Inputs are float64, positions in cm unless a name says m.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

from .._jit import njit
from ..env.geometry import nearest_pellet


class FieldConstants(NamedTuple):
    """The env's effect-plan constants (SI) that :func:`log_fields_kernel` needs; read from ``env.plan`` and
    ``env.cfg.physics`` by the caller, so the recorded fields are the simulated ones."""

    k: float              # 1 / (4 pi eps0), V m / C
    eod_charge: float     # C, +q ahead and -q behind the body centre
    half_sep: float       # m, from the body centre to each EOD monopole
    agent_dipole: float   # C m, along the body +x
    pellet_dipole: float  # C m, along the pellet +y
    alpha_agent: float    # induced moment per field, C m / (V/m)
    alpha_pellet: float
    soft2: float          # m^2, softening squared


@njit(cache=True, error_model="numpy")
def wrap(a):
    """Angle ``a`` (rad) wrapped to [-pi, pi): :func:`efish.units.wrap`, same operations, for one float."""
    return (a + np.pi) % (2 * np.pi) - np.pi


@njit(cache=True, error_model="numpy")
def bearing(dx, dy, heading):
    """Direction (rad) of (dx, dy) from ``heading``, wrapped to [-pi, pi)."""
    return wrap(np.arctan2(dy, dx) - heading)


@njit(cache=True, error_model="numpy")
def nearest_agents(xy, heading, size, dist, bear, dist2, size1, size2):
    """Nearest two other agents of each agent: ``dist`` (cm) and ``bear`` (rad) to the nearest, ``dist2`` (cm) to
    the second, ``size1``/``size2`` their sizes; all [B, N], NaN where there is no such agent.

    xy float64[B, N, 2] cm, heading [B, N] rad, size [B, N]. A tie goes to the lower index (stable order).
    """
    for b in range(xy.shape[0]):
        for i in range(xy.shape[1]):
            d1 = d2 = np.inf
            k1 = k2 = -1
            for j in range(xy.shape[1]):
                if j == i:
                    continue
                d = np.sqrt((xy[b, j, 0] - xy[b, i, 0]) ** 2 + (xy[b, j, 1] - xy[b, i, 1]) ** 2)
                if d < d1:  # strict: an equal later j ranks after the earlier one
                    d2, k2, d1, k1 = d1, k1, d, j
                elif d < d2:
                    d2, k2 = d, j
            if k1 >= 0:
                dist[b, i] = d1
                bear[b, i] = bearing(xy[b, k1, 0] - xy[b, i, 0], xy[b, k1, 1] - xy[b, i, 1], heading[b, i])
                size1[b, i] = size[b, k1]
            else:
                dist[b, i] = bear[b, i] = size1[b, i] = np.nan
            dist2[b, i] = d2 if k2 >= 0 else np.nan
            size2[b, i] = size[b, k2] if k2 >= 0 else np.nan


@njit(cache=True, error_model="numpy")
def nearest_food(xy, heading, pellet_xy, alive, dist, bear):
    """Distance (cm) and bearing (rad) to each agent's nearest live pellet into ``dist``, ``bear`` [B, N]; NaN
    when none is left. pellet_xy float64[B, P, 2] cm, alive bool[B, P]."""
    k = np.empty(dist.shape, np.int64)
    nearest_pellet(xy, pellet_xy, alive, dist, k)  # the one home of the nearest-pellet rule
    for b in range(xy.shape[0]):
        for i in range(xy.shape[1]):
            p = k[b, i]
            bear[b, i] = (bearing(pellet_xy[b, p, 0] - xy[b, i, 0], pellet_xy[b, p, 1] - xy[b, i, 1], heading[b, i])
                          if p >= 0 else np.nan)


@njit(cache=True, error_model="numpy")
def nearest_wall(xy, heading, width, height, dist, bear):
    """Distance (cm) and bearing (rad) to the nearest wall of each agent's arena (width, height [B] cm) into
    ``dist``, ``bear`` [B, N]. Walls in the order x = 0, x = W, y = 0, y = H; a tie goes to the earlier."""
    outward = (np.pi, 0.0, -np.pi / 2, np.pi / 2)  # direction of each wall from inside the arena
    for b in range(xy.shape[0]):
        for i in range(xy.shape[1]):
            x, y = xy[b, i, 0], xy[b, i, 1]
            gaps = (x, width[b] - x, y, height[b] - y)
            w = 0
            for c in range(1, 4):
                if gaps[c] < gaps[w]:
                    w = c
            dist[b, i] = gaps[w]
            bear[b, i] = wrap(outward[w] - heading[b, i])


@njit(cache=True, error_model="numpy")
def food_sectors(xy, heading, pellet_xy, alive, radius, counts):
    """Live pellets within ``radius`` (cm) of each agent into ``counts`` int64[5, B, N]: row 0 all of them, rows
    1-4 those whose bearing is nearest 0, pi/2, pi, -pi/2 (front, left, back, right; half-way rounds to even)."""
    counts[:] = 0
    r2 = radius * radius
    for b in range(xy.shape[0]):
        for i in range(xy.shape[1]):
            for p in range(pellet_xy.shape[1]):
                dx, dy = pellet_xy[b, p, 0] - xy[b, i, 0], pellet_xy[b, p, 1] - xy[b, i, 1]
                if alive[b, p] and dx * dx + dy * dy <= r2:
                    sector = int(np.rint(bearing(dx, dy, heading[b, i]) / (np.pi / 2))) % 4
                    counts[0, b, i] += 1
                    counts[1 + sector, b, i] += 1


@njit(cache=True, error_model="numpy")
def count_within(xy, range_cm, counts):
    """Other agents whose centre is closer (strictly) than ``range_cm`` to each agent's into ``counts`` [B, N]."""
    for b in range(xy.shape[0]):
        for i in range(xy.shape[1]):
            c = 0
            for j in range(xy.shape[1]):
                d = np.sqrt((xy[b, j, 0] - xy[b, i, 0]) ** 2 + (xy[b, j, 1] - xy[b, i, 1]) ** 2)
                if j != i and d < range_cm:
                    c += 1
            counts[b, i] = c


@njit(cache=True, error_model="numpy")
def dipole_terms(dx, dy, px, py, inv_r2, inv_r3):
    """3 (p.d) d / |d|^5 - p / |d|^3 at offset (dx, dy) m from a dipole p: its field over k. The softened
    inverse powers come from the caller, who shares them between the dipoles at one body."""
    p_dot_d = 3.0 * (px * dx + py * dy) * inv_r2
    return inv_r3 * (p_dot_d * dx - px), inv_r3 * (p_dot_d * dy - py)


@njit(cache=True, error_model="numpy")
def eod_at(x, y, ex, ey, ux, uy, soft2):
    """Field over k q at (x, y) m of an EOD at (ex, ey) m: +q at e + u, -q at e - u."""
    fx = fy = 0.0
    for sign in (1.0, -1.0):
        dx, dy = x - (ex + sign * ux), y - (ey + sign * uy)
        inv_r2 = 1.0 / (dx * dx + dy * dy + soft2)
        w = sign * inv_r2 * np.sqrt(inv_r2)
        fx += w * dx
        fy += w * dy
    return fx, fy


@njit(cache=True, error_model="numpy")
def live_bodies(xy_m, heading, pellet_m, pellet_phi, alive, b, c, src):
    """Bodies of arena ``b`` into the columns of ``src`` [5, >= N + P] (x m, y m, intrinsic moment x, y C m,
    polarisability): every agent, in order (so agent i is column i), then the live pellets. Returns how many.

    Done once per arena, so the trigonometry of the moments is not repeated for every agent that sees them.
    """
    m = 0
    for j in range(xy_m.shape[1]):
        src[0, m], src[1, m], src[4, m] = xy_m[b, j, 0], xy_m[b, j, 1], c.alpha_agent
        src[2, m], src[3, m] = c.agent_dipole * np.cos(heading[b, j]), c.agent_dipole * np.sin(heading[b, j])
        m += 1
    for k in range(pellet_m.shape[1]):
        if alive[b, k]:
            src[0, m], src[1, m], src[4, m] = pellet_m[b, k, 0], pellet_m[b, k, 1], c.alpha_pellet
            phi = pellet_phi[b, k]
            src[2, m], src[3, m] = -c.pellet_dipole * np.sin(phi), c.pellet_dipole * np.cos(phi)  # along pellet +y
            m += 1
    return m


@njit(cache=True, fastmath={"contract", "arcp", "reassoc"}, error_model="numpy")
def field_sums(src, lo, hi, cx, cy, ux, uy, kq, soft2):
    """Ampullary and Mormyromast fields over k at an agent's centre (cx, cy) m, with its EOD half-axis (ux, uy) m,
    of the bodies ``lo:hi`` of ``src`` (see :func:`live_bodies`): sums (ax, ay, mx, my).

    Loops over bodies innermost without a branch, so the sums vectorise (hence fastmath's reassociation, as in
    efish.physics.kernels); the rows are sliced first so the loop index starts at 0. The induced moment, alpha
    times the agent's EOD field at the body, is :func:`efish.physics.fields.induced_dipole`'s step written out
    per body, since a kernel cannot call that numpy function; tests/physics/test_induction.py holds the two equal.
    """
    x, y, px, py, alpha = src[0, lo:hi], src[1, lo:hi], src[2, lo:hi], src[3, lo:hi], src[4, lo:hi]
    ax = ay = mx = my = 0.0
    for j in range(x.shape[0]):
        fx, fy = eod_at(x[j], y[j], cx, cy, ux, uy, soft2)  # own EOD at the body: it induces alpha E there
        dx, dy = cx - x[j], cy - y[j]
        inv_r2 = 1.0 / (dx * dx + dy * dy + soft2)
        inv_r3 = inv_r2 * np.sqrt(inv_r2)
        ex, ey = dipole_terms(dx, dy, px[j], py[j], inv_r2, inv_r3)
        ax += ex
        ay += ey
        ex, ey = dipole_terms(dx, dy, alpha[j] * kq * fx, alpha[j] * kq * fy, inv_r2, inv_r3)
        mx += ex
        my += ey
    return ax, ay, mx, my


@njit(cache=True, error_model="numpy")
def log_fields_kernel(xy_m, heading, pellet_m, pellet_phi, alive, c, amp, morm):
    """log10 |E| (V/m) at each agent's centre into ``amp`` (intrinsic dipoles of every other body) and ``morm``
    (the dipoles the agent's own EOD induces on every other body), [B, N]; free space, live pellets only,
    -inf where the field is exactly 0.

    xy_m float64[B, N, 2] m, heading [B, N] rad, pellet_m [B, P, 2] m, pellet_phi [B, P] rad, alive bool[B, P],
    ``c`` a :class:`FieldConstants`.
    """
    kq = c.k * c.eod_charge
    src = np.empty((5, xy_m.shape[1] + pellet_m.shape[1]))
    for b in range(xy_m.shape[0]):
        m = live_bodies(xy_m, heading, pellet_m, pellet_phi, alive, b, c, src)
        for i in range(xy_m.shape[1]):
            cx, cy = xy_m[b, i, 0], xy_m[b, i, 1]
            ux, uy = c.half_sep * np.cos(heading[b, i]), c.half_sep * np.sin(heading[b, i])
            a1x, a1y, m1x, m1y = field_sums(src, 0, i, cx, cy, ux, uy, kq, c.soft2)  # agent i is column i: skip it
            a2x, a2y, m2x, m2y = field_sums(src, i + 1, m, cx, cy, ux, uy, kq, c.soft2)
            ax, ay, mx, my = a1x + a2x, a1y + a2y, m1x + m2x, m1y + m2y
            amp[b, i] = np.log10(c.k * np.sqrt(ax * ax + ay * ay))
            morm[b, i] = np.log10(c.k * np.sqrt(mx * mx + my * my))
