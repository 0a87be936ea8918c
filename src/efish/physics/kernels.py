"""Fast path: numba kernels for the raw receptor readings of a batch of arenas.

Same formulas as :mod:`efish.physics.reference`, evaluated source by source
with the culling rule of :mod:`efish.physics.plan`. Kernels are pure functions
of plain arrays. They are type-generic: every constant arrives in the ``consts``
array of the working dtype, so float32 inputs stay float32 throughout (a bare
float literal would promote to float64).

Two observations keep the inner loops short:
- fields are linear in the moments, so the gated Mormyromast reading
  g_self * self + g_cons * c * cons is the field of one combined moment per
  body: one dipole evaluation per (source, sensor) instead of two;
- sensors sit on a circle, so cos/sin of sensor angles come from one cos/sin
  of the heading and precomputed angle tables.
"""

from __future__ import annotations

import numpy as np
from numba import njit

# Indices into the ``consts`` array (module-level ints are compile-time constants).
K, Q, HALF_SEP, P_AGENT, P_PELLET, ALPHA_AGENT, ALPHA_PELLET, SOFT2, R_SENS = range(9)
TOL_MORM, TOL_AMP, ZERO_MORM, ZERO_AMP, KNOLL_ZERO, G_SELF, G_CONS, K_CONS = range(9, 17)
ONE, TWO, THREE, ZERO, N_CONSTS = 17, 18, 19, 20, 21
# Indices into the ``flags`` array.
DO_MORM, DO_AMP, DO_KNOLL, DO_INDUCTION, DO_WALLDIST, DO_PELLETS, CULL, N_FLAGS = range(8)

_FASTMATH = {"contract", "arcp", "reassoc"}  # no nnan/ninf: hard cases must keep their NaN checks


@njit(cache=True, fastmath=_FASTMATH)
def add_dipole(out, sx, sy, nx, ny, px, py, mx, my, soft2, one, three):
    """out[s] += (k p-field of the dipole (mx, my) at (px, py)) . n[s]; moments carry k."""
    for s in range(out.shape[0]):
        dx = sx[s] - px
        dy = sy[s] - py
        inv_r2 = one / (dx * dx + dy * dy + soft2)
        inv_r3 = inv_r2 * np.sqrt(inv_r2)
        p_dot_d = mx * dx + my * dy
        d_dot_n = dx * nx[s] + dy * ny[s]
        p_dot_n = mx * nx[s] + my * ny[s]
        out[s] += inv_r3 * (three * p_dot_d * d_dot_n * inv_r2 - p_dot_n)


@njit(cache=True, fastmath=_FASTMATH)
def add_monopole(out, sx, sy, nx, ny, px, py, kq, soft2, one):
    """out[s] += (field of charge q at (px, py)) . n[s]; kq = k * q."""
    for s in range(out.shape[0]):
        dx = sx[s] - px
        dy = sy[s] - py
        inv_r2 = one / (dx * dx + dy * dy + soft2)
        out[s] += kq * (dx * nx[s] + dy * ny[s]) * inv_r2 * np.sqrt(inv_r2)


@njit(cache=True, fastmath=_FASTMATH)
def monopole_at(x, y, px, py, kq, soft2, one):
    """Field (Ex, Ey) of a charge at one point."""
    dx = x - px
    dy = y - py
    inv_r2 = one / (dx * dx + dy * dy + soft2)
    f = kq * inv_r2 * np.sqrt(inv_r2)
    return f * dx, f * dy


@njit(cache=True)
def place_sensors(x, y, heading, cos_a, sin_a, radius, sx, sy, nx, ny):
    """Sensor positions and outward normals on a circle around (x, y)."""
    ch, sh = np.cos(heading), np.sin(heading)
    for s in range(cos_a.shape[0]):
        nx[s] = ch * cos_a[s] - sh * sin_a[s]
        ny[s] = sh * cos_a[s] + ch * sin_a[s]
        sx[s] = x + radius * nx[s]
        sy[s] = y + radius * ny[s]


@njit(cache=True, fastmath=_FASTMATH)
def gather_dipoles(ax, ay, bx, by, mx, my, skip, img, c, threshold, cand):
    """Collect the wall images of body dipoles whose bound at the agent is >= threshold.

    ax, ay: agent centre; bx, by, mx, my: body positions and moments (k folded
    in), ``skip`` a body index whose identity image is left out (-1: none);
    ``img`` rows are (x offset, x sign, y offset, y sign, weight). Candidates go
    to ``cand`` rows (x, y, mx, my). Returns (count, sum of all bounds).
    """
    r = c[R_SENS]
    count, total = 0, 0.0  # bounds only steer decisions: float64 whatever the dtype
    for j in range(bx.shape[0]):
        mag = np.sqrt(mx[j] * mx[j] + my[j] * my[j])
        if mag == 0:
            continue
        for i in range(img.shape[0]):
            if j == skip and i == 0:
                continue
            x = img[i, 0] + img[i, 1] * bx[j]
            y = img[i, 2] + img[i, 3] * by[j]
            dist = np.sqrt((x - ax) ** 2 + (y - ay) ** 2) - r
            bound = 2.0 * mag * img[i, 4] / (dist * dist * dist) if dist > 0 else np.inf
            total += bound
            if bound < threshold:
                continue
            w = img[i, 4]
            cand[count, 0] = x
            cand[count, 1] = y
            cand[count, 2] = img[i, 1] * w * mx[j]
            cand[count, 3] = img[i, 3] * w * my[j]
            count += 1
    return count, total


@njit(cache=True)
def image_table(width, height, idx, weights, c):
    """Rows (x offset, x sign, y offset, y sign, weight) mapping a source to each image."""
    table = np.empty((idx.shape[0], 5), dtype=c.dtype)
    for i in range(idx.shape[0]):
        for axis, length in ((0, width), (1, height)):
            n = idx[i, axis]
            odd = n % 2 != 0
            table[i, 2 * axis] = (n + 1) * length if odd else n * length
            table[i, 2 * axis + 1] = -c[ONE] if odd else c[ONE]
        table[i, 4] = weights[i]
    return table


@njit(cache=True, fastmath=_FASTMATH)
def induced_dipoles(axy, heading, emitting, bx, by, alpha, img, c, p_ind):
    """p_ind[body, e] = alpha_body * E_e(body) for every emitter e, own EOD excluded (SPEC 2.3).

    E_e is the field of e's two monopoles and all their wall images.
    """
    kq = c[K] * c[Q]
    for e in range(axy.shape[0]):
        if not emitting[e]:
            continue
        ux = c[HALF_SEP] * np.cos(heading[e])
        uy = c[HALF_SEP] * np.sin(heading[e])
        for j in range(bx.shape[0]):
            if j == e:
                continue
            ex = ey = c[ZERO]
            for i in range(img.shape[0]):
                for sign in (c[ONE], -c[ONE]):
                    mx = img[i, 0] + img[i, 1] * (axy[e, 0] + sign * ux)
                    my = img[i, 2] + img[i, 3] * (axy[e, 1] + sign * uy)
                    fx, fy = monopole_at(bx[j], by[j], mx, my, sign * kq * img[i, 4], c[SOFT2], c[ONE])
                    ex += fx
                    ey += fy
            p_ind[j, e, 0] = alpha[j] * ex
            p_ind[j, e, 1] = alpha[j] * ey


@njit(cache=True, fastmath=_FASTMATH)
def knollenorgan_env(axy, heading, emitting, cos_k, sin_k, c, flags, out):
    """out[a, slot] = direct EOD field of the slot's conspecific at a's sensors, no images."""
    n = axy.shape[0]
    s_count = cos_k.shape[0]
    sx, sy = np.empty(s_count, c.dtype), np.empty(s_count, c.dtype)
    nx, ny = np.empty(s_count, c.dtype), np.empty(s_count, c.dtype)
    kq = c[K] * c[Q]
    for a in range(n):
        placed = False
        slot = -1
        for j in range(n):
            if j == a:
                continue
            slot += 1
            if not emitting[j]:
                continue
            # Mean-value bound on the pair field: |E| <= 2 h * 2 k q / (D - r - h)^3.
            dist = np.sqrt((axy[j, 0] - axy[a, 0]) ** 2 + (axy[j, 1] - axy[a, 1]) ** 2) - c[R_SENS] - c[HALF_SEP]
            if flags[CULL] and dist > 0 and 4.0 * kq * c[HALF_SEP] / dist ** 3 <= c[KNOLL_ZERO]:
                continue  # every spike would be 0 after binarisation
            if not placed:
                place_sensors(axy[a, 0], axy[a, 1], heading[a], cos_k, sin_k, c[R_SENS], sx, sy, nx, ny)
                placed = True
            ux = c[HALF_SEP] * np.cos(heading[j])
            uy = c[HALF_SEP] * np.sin(heading[j])
            add_monopole(out[a, slot], sx, sy, nx, ny, axy[j, 0] + ux, axy[j, 1] + uy, kq, c[SOFT2], c[ONE])
            add_monopole(out[a, slot], sx, sy, nx, ny, axy[j, 0] - ux, axy[j, 1] - uy, -kq, c[SOFT2], c[ONE])


@njit(cache=True, fastmath=_FASTMATH)
def evaluate_candidates(out, cand, count, sx, sy, nx, ny, c):
    """Add the fields of the first ``count`` candidate dipoles to ``out``."""
    for q in range(count):
        add_dipole(out, sx, sy, nx, ny, cand[q, 0], cand[q, 1], cand[q, 2], cand[q, 3],
                   c[SOFT2], c[ONE], c[THREE])


@njit(cache=True, fastmath=_FASTMATH)
def sense_env(axy, heading, emitting, bx, by, bmx, bmy, alpha, img, c, flags,
              cos_m, sin_m, cos_a, sin_a, cos_k, sin_k, p_ind, cand, out_m, out_a, out_k):
    """Raw readings of one arena. Bodies are agents (first N) then live pellets.

    bx, by: body centres, m; bmx, bmy: intrinsic moments times k; alpha: induced
    moment per field; p_ind, cand: scratch of at least (bodies, N, 2) and
    (bodies * images, 4). Writes out_m (N, Sm), out_a (N, Sa), out_k (N, N-1, Sk).
    """
    n, nb = axy.shape[0], bx.shape[0]
    sm, sa = cos_m.shape[0], cos_a.shape[0]
    sx, sy = np.empty(max(sm, sa), c.dtype), np.empty(max(sm, sa), c.dtype)
    nx, ny = np.empty(max(sm, sa), c.dtype), np.empty(max(sm, sa), c.dtype)
    any_emitter = False
    for e in range(n):
        any_emitter = any_emitter or emitting[e]
    induction = flags[DO_INDUCTION] and any_emitter
    if induction:
        p_ind[:nb, :n] = c[ZERO]
        induced_dipoles(axy, heading, emitting, bx, by, alpha, img, c, p_ind)
    mx, my = np.empty(nb, c.dtype), np.empty(nb, c.dtype)
    for a in range(n):
        # -------- Mormyromasts: one combined moment per body (gates folded in)
        if flags[DO_MORM] and (induction or (flags[DO_WALLDIST] and emitting[a])):
            gain = c[K_CONS] if (not emitting[a] or c[G_SELF] == 0) else c[ONE]
            for j in range(nb):
                mx[j] = my[j] = c[ZERO]
                if induction and j != a:
                    for e in range(n):
                        w = c[G_SELF] if e == a else c[G_CONS] * gain
                        mx[j] += w * p_ind[j, e, 0]
                        my[j] += w * p_ind[j, e, 1]
                    mx[j] *= c[K]
                    my[j] *= c[K]
            thr = c[TOL_MORM] if flags[CULL] else -1.0
            count, total = gather_dipoles(axy[a, 0], axy[a, 1], bx, by, mx, my, -1, img, c, thr, cand)
            walls = flags[DO_WALLDIST] and emitting[a] and img.shape[0] > 1 and c[G_SELF] != c[ZERO]
            if walls or not flags[CULL] or total > c[ZERO_MORM]:
                place_sensors(axy[a, 0], axy[a, 1], heading[a], cos_m, sin_m, c[R_SENS], sx[:sm], sy[:sm], nx[:sm], ny[:sm])
                evaluate_candidates(out_m[a], cand, count, sx[:sm], sy[:sm], nx[:sm], ny[:sm], c)
                if walls:
                    own_eod_images(out_m[a], axy[a], heading[a], img, c, sx[:sm], sy[:sm], nx[:sm], ny[:sm])
        # -------- Ampullary organs: intrinsic dipoles, own one through its images only
        if flags[DO_AMP]:
            count, total = gather_dipoles(axy[a, 0], axy[a, 1], bx, by, bmx, bmy, a, img, c,
                                          c[TOL_AMP] if flags[CULL] else -1.0, cand)
            if not flags[CULL] or total > c[ZERO_AMP]:
                place_sensors(axy[a, 0], axy[a, 1], heading[a], cos_a, sin_a, c[R_SENS], sx[:sa], sy[:sa], nx[:sa], ny[:sa])
                evaluate_candidates(out_a[a], cand, count, sx[:sa], sy[:sa], nx[:sa], ny[:sa], c)
    if flags[DO_KNOLL] and any_emitter:
        knollenorgan_env(axy, heading, emitting, cos_k, sin_k, c, flags, out_k)


@njit(cache=True, fastmath=_FASTMATH)
def own_eod_images(out, xy, heading, img, c, sx, sy, nx, ny):
    """The wall images (not the EOD itself) of an agent's own monopoles at its sensors, times g_self
    (they are part of the self image, SPEC 3.1)."""
    ux = c[HALF_SEP] * np.cos(heading)
    uy = c[HALF_SEP] * np.sin(heading)
    for i in range(1, img.shape[0]):
        for sign in (c[ONE], -c[ONE]):
            px = img[i, 0] + img[i, 1] * (xy[0] + sign * ux)
            py = img[i, 2] + img[i, 3] * (xy[1] + sign * uy)
            add_monopole(out, sx, sy, nx, ny, px, py, sign * c[G_SELF] * c[K] * c[Q] * img[i, 4], c[SOFT2], c[ONE])


@njit(cache=True)
def sense_batch_kernel(agent_xy, heading, emitting, pellet_xy, pellet_phi, pellet_alive, width, height,
                       img_idx, img_w, c, flags, cos_m, sin_m, cos_a, sin_a, cos_k, sin_k,
                       out_m, out_a, out_k):
    """Raw readings for B arenas. Positions in m, in the dtype of ``c``; outputs zeroed by the caller."""
    b_count, n = agent_xy.shape[0], agent_xy.shape[1]
    p_max = pellet_xy.shape[1] if flags[DO_PELLETS] else 0
    nb_max = n + p_max
    p_ind = np.empty((nb_max, n, 2), c.dtype)
    cand = np.empty((nb_max * img_idx.shape[0], 4), c.dtype)
    bx, by = np.empty(nb_max, c.dtype), np.empty(nb_max, c.dtype)
    bmx, bmy = np.empty(nb_max, c.dtype), np.empty(nb_max, c.dtype)
    alpha = np.empty(nb_max, c.dtype)
    for b in range(b_count):
        img = image_table(width[b], height[b], img_idx, img_w, c)
        nb = 0
        for j in range(n):
            bx[nb], by[nb], alpha[nb] = agent_xy[b, j, 0], agent_xy[b, j, 1], c[ALPHA_AGENT]
            bmx[nb] = c[K] * c[P_AGENT] * np.cos(heading[b, j])
            bmy[nb] = c[K] * c[P_AGENT] * np.sin(heading[b, j])
            nb += 1
        for j in range(p_max):
            if pellet_alive[b, j]:
                bx[nb], by[nb], alpha[nb] = pellet_xy[b, j, 0], pellet_xy[b, j, 1], c[ALPHA_PELLET]
                bmx[nb] = -c[K] * c[P_PELLET] * np.sin(pellet_phi[b, j])
                bmy[nb] = c[K] * c[P_PELLET] * np.cos(pellet_phi[b, j])
                nb += 1
        sense_env(agent_xy[b], heading[b], emitting[b], bx[:nb], by[:nb], bmx[:nb], bmy[:nb], alpha[:nb],
                  img, c, flags, cos_m, sin_m, cos_a, sin_a, cos_k, sin_k, p_ind, cand,
                  out_m[b], out_a[b], out_k[b])
