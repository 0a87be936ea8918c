"""Per-agent assembly of raw readings in numba: culling, exact and interpolated sources.

For each agent the sources (every body and its wall images) are gathered once
with two moment columns, the combined Mormyromast moment and the intrinsic
(Ampullary) moment, culled by the bound of :mod:`efish.physics.plan`.

With culling on (tolerance > 0) a source at distance D is not evaluated at
every sensor when that is not needed: the reading of a dipole on the sensor
circle (radius r) is a smooth periodic function of the angle whose Fourier
modes decay like (r / D)^m, so its values at Q evenly spaced points carry it
to the sensors by trigonometric interpolation with an error below
C Q B (r/D)^((Q+1)/2) (B the source's bound, C = ``far_field_safety``; the
factor was measured, then padded). Each source goes to the level with the
smallest Q whose error stays below tolerance * E_min (bucket 0: exact at
every sensor). ``efish bench accuracy`` measures the result.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from .kernels import (
    _FASTMATH, ALPHA_AGENT, ALPHA_PELLET, CULL, DO_AMP, DO_INDUCTION, DO_KNOLL, DO_MORM, DO_PELLETS,
    DO_WALLDIST, FAR_MAX_LS, FAR_MAX_LX, G_CONS, G_SELF, HALF_SEP, K, K_CONS, KNOLL_ZERO, M1X, M1Y, M2X, M2Y, N_SRC, ONE,
    P_AGENT, P_PELLET, Q, R_SENS, SOFT2, SX, SY, TOL_AMP, TOL_MORM, ZERO, ZERO_AMP, ZERO_MORM,
    add_dipole, add_monopole, far_readings, image_table, induced_dipoles, place_on_circle, place_sensors,
)


@njit(cache=True, fastmath=_FASTMATH, error_model="numpy")
def image_bounds(ax, ay, bx, by, sig, img, r, geo):
    """Positions, unit-moment bounds 2 w / (D - r)^3, significance and D^2 of every body image seen from (ax, ay).

    Branch-free over bodies so it vectorises; column k = i * bodies + j of
    ``geo`` holds rows (x, y, bound, -, bound * sig[j], D^2), where ``sig``
    is a body's larger moment / threshold ratio, so row 4 is the source's
    bound / threshold. A source inside the sensor circle gets a huge bound.
    """
    nb = bx.shape[0]
    for i in range(img.shape[0]):
        ox, sx, oy, sy, w = img[i, 0], img[i, 1], img[i, 2], img[i, 3], img[i, 4]
        for j in range(nb):
            x = ox + sx * bx[j]
            y = oy + sy * by[j]
            d2 = (x - ax) * (x - ax) + (y - ay) * (y - ay)
            gap = max(np.sqrt(d2) - r, 1e-100)
            unit = 2.0 * w / (gap * gap * gap)
            geo[0, i * nb + j] = x
            geo[1, i * nb + j] = y
            geo[2, i * nb + j] = unit
            geo[4, i * nb + j] = unit * sig[j] + 1e-300  # > 0: its log2 stays finite
            geo[5, i * nb + j] = d2 + 1e-300


MITCHELL_ERROR = 0.0861  # max of log2(1 + f) - f on [0, 1]: the bit-pattern log2 is at most this low


@njit(cache=True, fastmath=_FASTMATH, error_model="numpy")
def log2_upper(values, out):
    """out >= log2(values) within 0.09, from the float bit pattern (Mitchell); vectorises, no libm call."""
    bits = values.view(np.int64)
    for k in range(values.shape[0]):
        out[k] = bits[k] * 2.0 ** -52 - 1023.0 + MITCHELL_ERROR


@njit(cache=True, fastmath=_FASTMATH, error_model="numpy")
def interpolation_levels(n, geo, level_lcq, level_e, c, out):
    """Bucket of every source: the first level whose error bound C Q B x^e stays <= the threshold.

    In log2 the condition of level l is log2(C Q_l) + ls + e_l lx <= 0, with
    upper bounds ``ls`` >= log2(bound / threshold) (from ``geo`` row 4) and
    lx >= log2(r / D) (from ``geo`` row 5), so the choice errs towards
    accuracy. The bound falls with the level, so the bucket is 1 + the number
    of failing levels, or 0 (exact) when every level fails or the source is
    closer than the far-field minimum, or so strong (bound / threshold >
    2^FAR_MAX_LS) that float32, in which interpolated sources are evaluated,
    would round off more than the threshold. Written as counts over levels,
    branch-free (``|``, not ``or``), so it vectorises.
    """
    n_lv = level_e.shape[0]
    ls, lx = geo[4, :n], geo[5, :n]
    log2_upper(ls, ls)
    log2_upper(lx, lx)
    log2_r = math.log2(c[R_SENS])
    for k in range(n):
        lx[k] = log2_r - 0.5 * (lx[k] - MITCHELL_ERROR)
        out[k] = 0
    for lv in range(n_lv):  # levels outermost: the loop over sources vectorises
        lcq, e = level_lcq[lv], level_e[lv]
        for k in range(n):
            out[k] += lcq + ls[k] + e * lx[k] > 0
    for k in range(n):
        exact = (out[k] == n_lv) | (lx[k] > c[FAR_MAX_LX]) | (ls[k] > c[FAR_MAX_LS])
        out[k] = 0 if exact else out[k] + 1


@njit(cache=True, fastmath=_FASTMATH, error_model="numpy")
def gather_sources(a, ax, ay, bx, by, m1x, m1y, m2x, m2y, img, c, thr1, thr2, level_lcq, level_e,
                   geo, level, keep, exact, far, offsets):
    """Images of body moments whose bound at agent ``a`` reaches a threshold, bucketed by level.

    Column 1 (Mormyromast) and column 2 (Ampullary) are culled separately; a
    culled column is stored as 0. The agent's own intrinsic dipole enters only
    through its images. Bucket l holds sources ``offsets[l]:offsets[l + 1]``:
    the exact ones (bucket 0) go to ``exact`` in the working dtype, the
    interpolated ones straight to the same columns of ``far`` in float32,
    positions relative to the agent (where float32 is precise). ``geo`` rows 4-5 receive upper bounds of
    log2(bound / threshold) and log2(r / D), ``level`` the bucket of every
    source, ``keep`` which columns survive culling. Returns the bound sums of
    both columns.
    """
    nb, n_img = bx.shape[0], img.shape[0]
    n = nb * n_img
    inv1 = 1.0 / thr1 if thr1 > 0 else 0.0
    inv2 = 1.0 / thr2 if thr2 > 0 else 0.0
    mag1, mag2, sig = np.empty(nb), np.empty(nb), np.empty(nb)
    for j in range(nb):
        mag1[j] = np.sqrt(m1x[j] * m1x[j] + m1y[j] * m1y[j])
        mag2[j] = np.sqrt(m2x[j] * m2x[j] + m2y[j] * m2y[j])
        sig[j] = max(mag1[j] * inv1, mag2[j] * inv2)  # the larger column: a conservative significance
    image_bounds(ax, ay, bx, by, sig, img, c[R_SENS], geo)
    level[:n] = 0
    if level_e.shape[0] > 0:
        interpolation_levels(n, geo, level_lcq, level_e, c, level)
    # the agent's own intrinsic dipole enters through its images only (its own induced
    # moment is already 0): drop the identity image, whose bound is huge (it sits on the body)
    geo[2, a] = 0.0
    total1 = total2 = 0.0  # bounds steer decisions only: float64 whatever the dtype
    for i in range(n_img):  # cull, branch-free (``&``, not ``and``) so it vectorises
        for j in range(nb):
            k = i * nb + j
            b1 = mag1[j] * geo[2, k]
            b2 = mag2[j] * geo[2, k]
            total1 += b1
            total2 += b2
            keep[k] = ((mag1[j] > 0) & (b1 >= thr1)) * 1 + ((mag2[j] > 0) & (b2 >= thr2)) * 2
    keep[a] = 0
    # counting sort by bucket: bucket l > 0 fills far[:, offsets[l]:offsets[l + 1]], one compact
    # block that stays in L1 cache (one plane per level would spread the writes over ~100 kB)
    offsets[:] = 0
    for k in range(n):
        offsets[level[k] + 1] += keep[k] != 0
    for lv in range(offsets.shape[0] - 1):
        offsets[lv + 1] += offsets[lv]
    fill = offsets[:-1].copy()
    for i in range(n_img):
        w, sx, sy = img[i, 4], img[i, 1], img[i, 3]
        for j in range(nb):
            k = i * nb + j
            if keep[k] == 0:
                continue
            lv = level[k]
            q = fill[lv]
            fill[lv] += 1
            w1, w2 = w * (keep[k] & 1), w * (keep[k] >> 1)  # 0 for a culled column
            if lv == 0:
                exact[SX, q], exact[SY, q] = geo[0, k], geo[1, k]
                exact[M1X, q], exact[M1Y, q] = sx * w1 * m1x[j], sy * w1 * m1y[j]
                exact[M2X, q], exact[M2Y, q] = sx * w2 * m2x[j], sy * w2 * m2y[j]
            else:
                far[SX, q], far[SY, q] = geo[0, k] - ax, geo[1, k] - ay
                far[M1X, q], far[M1Y, q] = sx * w1 * m1x[j], sy * w1 * m1y[j]
                far[M2X, q], far[M2Y, q] = sx * w2 * m2x[j], sy * w2 * m2y[j]
    return total1, total2


@njit(cache=True, fastmath=_FASTMATH, error_model="numpy")
def mormyromast_moments(a, emitting, p_ind, c, mx, my):
    """g_self * self + g_cons * gain * cons moment of every body for agent ``a`` (k folded in).

    self = p_ind[a] (zero when a is silent), cons = sum of p_ind[e] over the
    other emitters; gain = k_cons when ``a`` is silent or g_self = 0 (SPEC 3.1).
    The agent's own induced dipole is excluded (the body is the sensor).
    cons is summed directly, not formed as p_sum - p_ind[a]: near an emitting
    agent self >> cons, and the difference would lose cons to round-off (in
    float32 by up to ~0.3 after normalisation, times k_cons in cons-only runs).
    ``p_ind`` may have room for more bodies than ``mx``; rows are sliced to fit.
    """
    gain = c[K_CONS] if (not emitting[a] or c[G_SELF] == 0) else c[ONE]
    w_cons = c[G_CONS] * gain * c[K]
    w_self = c[G_SELF] * c[K]
    nb = mx.shape[0]
    sx, sy = p_ind[a, 0, :nb], p_ind[a, 1, :nb]
    for j in range(nb):
        mx[j] = w_self * sx[j]
        my[j] = w_self * sy[j]
    for e in range(emitting.shape[0]):
        if e != a and emitting[e]:
            ex, ey = p_ind[e, 0, :nb], p_ind[e, 1, :nb]
            for j in range(nb):
                mx[j] += w_cons * ex[j]
                my[j] += w_cons * ey[j]
    mx[a] = c[ZERO]
    my[a] = c[ZERO]


@njit(cache=True, fastmath=_FASTMATH, error_model="numpy")
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


@njit(cache=True, fastmath=_FASTMATH, error_model="numpy")
def knollenorgan_env(axy, heading, emitting, cos_k, sin_k, c, flags, out):
    """out[a, slot] = direct EOD field of the slot's conspecific at a's sensors, no images."""
    n, s_count = axy.shape[0], cos_k.shape[0]
    sx, sy = np.empty(s_count, c.dtype), np.empty(s_count, c.dtype)
    nx, ny = np.empty(s_count, c.dtype), np.empty(s_count, c.dtype)
    kq = c[K] * c[Q]
    for a in range(n):
        place_sensors(axy[a, 0], axy[a, 1], heading[a], cos_k, sin_k, c[R_SENS], sx, sy, nx, ny)
        slot = -1
        for j in range(n):
            if j == a:
                continue
            slot += 1
            if not emitting[j]:
                continue
            # Mean-value bound on the pair field: |E| <= 2 h * 2 k q / (D - r - h)^3.
            gap = np.sqrt((axy[j, 0] - axy[a, 0]) ** 2 + (axy[j, 1] - axy[a, 1]) ** 2) - c[R_SENS] - c[HALF_SEP]
            if flags[CULL] and gap > 0 and 4.0 * kq * c[HALF_SEP] / gap ** 3 <= c[KNOLL_ZERO]:
                continue  # every spike would be 0 after binarisation
            ux = c[HALF_SEP] * np.cos(heading[j])
            uy = c[HALF_SEP] * np.sin(heading[j])
            add_monopole(out[a, slot], sx, sy, nx, ny, axy[j, 0] + ux, axy[j, 1] + uy, kq, c[SOFT2], c[ONE])
            add_monopole(out[a, slot], sx, sy, nx, ny, axy[j, 0] - ux, axy[j, 1] - uy, -kq, c[SOFT2], c[ONE])


@njit(cache=True, fastmath=_FASTMATH, error_model="numpy")
def add_sources(out, src, count, col_x, col_y, sx, sy, nx, ny, c):
    """Add the dipoles of column (col_x, col_y) of ``src[:count]`` at every sensor."""
    for i in range(count):
        if src[col_x, i] != 0 or src[col_y, i] != 0:
            add_dipole(out, sx, sy, nx, ny, src[SX, i], src[SY, i], src[col_x, i], src[col_y, i],
                       c[SOFT2], c[ONE], c[ONE] + c[ONE] + c[ONE])


@njit(cache=True, fastmath=_FASTMATH, error_model="numpy")
def interpolate_add(out, matrix, values):
    """out += matrix @ values: trigonometric interpolation from the points of every level to the sensors.

    ``matrix`` is (sensors, points), so each sensor is one dot product over
    contiguous points, summed in registers (levels without sources carry zeros).
    """
    for s in range(out.shape[0]):
        row = matrix[s]
        acc = out[s] - out[s]
        for q in range(values.shape[0]):
            acc += row[q] * values[q]
        out[s] += acc


@njit(cache=True, fastmath=_FASTMATH, error_model="numpy")
def sense_agent(a, axy, heading, emitting, bx, by, m1x, m1y, m2x, m2y, img, c, c32, flags, tables, levels,
                level_lcq, level_e, far_offsets, far_points, interp_m, interp_a, geo, level, keep, exact, far, offsets,
                scratch, scratch32, out_m, out_a):
    """Mormyromast and Ampullary raw readings of agent ``a``.

    ``tables`` rows 0-1 / 2-3: cos, sin of Mormyromast / Ampullary angles.
    ``scratch`` rows 0-3: sensor x, y, nx, ny; rows 4-5: readings at the points of
    every level (``scratch32``: the same in float32 for the interpolated sources,
    ``c32`` the constants in float32); level l owns points
    ``far_offsets[l]:far_offsets[l + 1]`` of ``far_points`` and rows of ``interp_m/a``.
    """
    sm, sa = out_m.shape[0], out_a.shape[0]
    ax, ay = axy[a, 0], axy[a, 1]
    thr1 = c[TOL_MORM] if flags[CULL] else -1.0
    thr2 = c[TOL_AMP] if flags[CULL] else -1.0
    tot1, tot2 = gather_sources(a, ax, ay, bx, by, m1x, m1y, m2x, m2y, img, c, thr1, thr2, level_lcq, level_e,
                                geo, level, keep, exact, far, offsets)
    walls = flags[DO_WALLDIST] and emitting[a] and img.shape[0] > 1 and c[G_SELF] != 0
    do_m = flags[DO_MORM] and (walls or not flags[CULL] or tot1 > c[ZERO_MORM])
    do_a = flags[DO_AMP] and (not flags[CULL] or tot2 > c[ZERO_AMP])
    sx, sy, nx, ny = scratch[0], scratch[1], scratch[2], scratch[3]
    if do_m:
        place_sensors(ax, ay, heading[a], tables[0, :sm], tables[1, :sm], c[R_SENS], sx[:sm], sy[:sm], nx[:sm], ny[:sm])
        add_sources(out_m, exact, offsets[1], M1X, M1Y, sx[:sm], sy[:sm], nx[:sm], ny[:sm], c)
        if walls:
            own_eod_images(out_m, axy[a], heading[a], img, c, sx[:sm], sy[:sm], nx[:sm], ny[:sm])
    if do_a:
        place_sensors(ax, ay, heading[a], tables[2, :sa], tables[3, :sa], c[R_SENS], sx[:sa], sy[:sa], nx[:sa], ny[:sa])
        add_sources(out_a, exact, offsets[1], M2X, M2Y, sx[:sa], sy[:sa], nx[:sa], ny[:sa], c)
    if not (do_m or do_a) or offsets[-1] == offsets[1]:
        return
    # the points of every level at once: one cos/sin of the heading per agent
    n_pts = far_offsets[-1]
    px, py, pnx, pny = scratch32[0, :n_pts], scratch32[1, :n_pts], scratch32[2, :n_pts], scratch32[3, :n_pts]
    place_on_circle(np.float32(0.0), np.float32(0.0), np.float32(np.cos(heading[a])), np.float32(np.sin(heading[a])),
                    far_points[0], far_points[1], c32[R_SENS], px, py, pnx, pny)
    for lv in range(levels.shape[0]):
        lo, hi = far_offsets[lv], far_offsets[lv + 1]
        if offsets[lv + 2] == offsets[lv + 1]:
            scratch32[4, lo:hi] = 0.0
            scratch32[5, lo:hi] = 0.0
            continue
        # interpolated sources are evaluated in float32 (twice the SIMD width, far
        # cheaper sqrt and division); positions relative to the agent keep it precise
        far_readings(far, offsets[lv + 1], offsets[lv + 2], px[lo:hi], py[lo:hi], pnx[lo:hi], pny[lo:hi], c32,
                     scratch32[4, lo:hi], scratch32[5, lo:hi])
    scratch[4, :n_pts] = scratch32[4, :n_pts]
    scratch[5, :n_pts] = scratch32[5, :n_pts]
    if do_m:
        interpolate_add(out_m, interp_m, scratch[4, :n_pts])
    if do_a:
        interpolate_add(out_a, interp_a, scratch[5, :n_pts])


@njit(cache=True, error_model="numpy")
def sense_batch_kernel(agent_xy, heading, emitting, pellet_xy, pellet_phi, pellet_alive, width, height,
                       img_idx, img_w, c, flags, tables, levels, level_lcq, level_e, far_offsets, far_points,
                       interp_m, interp_a, cos_k, sin_k,
                       out_m, out_a, out_k):
    """Raw readings for B arenas. Positions in m, in the dtype of ``c``; outputs zeroed by the caller.

    Bodies are the agents (first N) then the live pellets of each arena.
    """
    b_count, n = agent_xy.shape[0], agent_xy.shape[1]
    nb_max = n + (pellet_xy.shape[1] if flags[DO_PELLETS] else 0)
    cap = nb_max * img_idx.shape[0]
    exact = np.empty((N_SRC, cap), c.dtype)
    far = np.empty((N_SRC, cap), np.float32)
    offsets = np.zeros(levels.shape[0] + 2, np.int64)  # bucket l: sources offsets[l]:offsets[l + 1]
    c32 = c.astype(np.float32)
    geo = np.empty((6, cap), np.float64)
    level = np.zeros(cap, np.int64)
    keep = np.zeros(cap, np.int64)
    scratch = np.empty((6, max(tables.shape[1], far_points.shape[1])), c.dtype)
    scratch32 = np.empty((6, far_points.shape[1]), np.float32)
    p_ind = np.zeros((n, 2, nb_max), c.dtype)  # per emitter: induced moments of every body
    body = np.empty((7, nb_max), c.dtype)  # x, y, alpha, m1x, m1y, m2x, m2y
    for b in range(b_count):
        img = image_table(width[b], height[b], img_idx, img_w, c)
        nb = 0
        for j in range(n):
            body[0, nb], body[1, nb], body[2, nb] = agent_xy[b, j, 0], agent_xy[b, j, 1], c[ALPHA_AGENT]
            body[5, nb] = c[K] * c[P_AGENT] * np.cos(heading[b, j]) if flags[DO_AMP] else c[ZERO]
            body[6, nb] = c[K] * c[P_AGENT] * np.sin(heading[b, j]) if flags[DO_AMP] else c[ZERO]
            nb += 1
        for j in range(nb_max - n):
            if pellet_alive[b, j]:
                body[0, nb], body[1, nb], body[2, nb] = pellet_xy[b, j, 0], pellet_xy[b, j, 1], c[ALPHA_PELLET]
                body[5, nb] = -c[K] * c[P_PELLET] * np.sin(pellet_phi[b, j]) if flags[DO_AMP] else c[ZERO]
                body[6, nb] = c[K] * c[P_PELLET] * np.cos(pellet_phi[b, j]) if flags[DO_AMP] else c[ZERO]
                nb += 1
        induction = False
        if flags[DO_INDUCTION]:
            for e in range(n):
                induction = induction or emitting[b, e]
        if induction:
            induced_dipoles(agent_xy[b], heading[b], emitting[b], body[0, :nb], body[1, :nb], body[2, :nb], img, c,
                            p_ind)
        for a in range(n if (flags[DO_MORM] or flags[DO_AMP]) else 0):
            if flags[DO_MORM] and induction:
                mormyromast_moments(a, emitting[b], p_ind, c, body[3, :nb], body[4, :nb])
            else:
                body[3, :nb] = c[ZERO]
                body[4, :nb] = c[ZERO]
            sense_agent(a, agent_xy[b], heading[b], emitting[b], body[0, :nb], body[1, :nb], body[3, :nb],
                        body[4, :nb], body[5, :nb], body[6, :nb], img, c, c32, flags, tables, levels, level_lcq, level_e, far_offsets, far_points,
                        interp_m, interp_a, geo, level, keep, exact, far, offsets, scratch, scratch32, out_m[b, a], out_a[b, a])
        if flags[DO_KNOLL]:
            knollenorgan_env(agent_xy[b], heading[b], emitting[b], cos_k, sin_k, c, flags, out_k[b])
