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

Most sources belong to the first level. Sorting each into its bucket cost more
than evaluating them, so the first level is evaluated densely: one long loop
over every source, with the moments of the others zeroed. Only the few other
sources are bucketed, and every bucket is padded to whole SIMD blocks of inert
sources, because a loop of a few tens of iterations otherwise spends most of
its time in the scalar remainder.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from .kernels import (
    _FASTMATH, ALPHA_AGENT, ALPHA_PELLET, CULL, DO_AMP, DO_INDUCTION, DO_KNOLL, DO_MORM, DO_PELLETS,
    DO_WALLDIST, FAR_MAX_LS, FAR_MAX_LX, G_CONS, G_SELF, HALF_SEP, K, K_CONS, KNOLL_ZERO, M1X, M1Y, M2X, M2Y, N_SRC, ONE,
    P_AGENT, P_PELLET, Q, R_SENS, SOFT2, SX, SY, THREE, TOL_AMP, TOL_MORM, ZERO, ZERO_AMP, ZERO_MORM,
    add_monopole, far_readings, image_table, induced_dipoles, place_on_circle, place_sensors,
)
from .trig import sincos


# Rows of the per-source staging array ``geo`` (float64, one column per body image).
G_X, G_Y, G_M1X, G_M1Y, G_M2X, G_M2Y, G_LS, G_LX, G_KEEP, G_UNIT, N_GEO = range(11)
# Sources per SIMD block, measured best: float32 loops over 24 sources take longer than over 32
# (a scalar remainder), float64 loops over sensors x sources pay per 8 sources.
BLOCK = 16
EXACT_BLOCK = 8
MITCHELL_ERROR = 0.0861  # max of log2(1 + f) - f on [0, 1]: the bit-pattern log2 is at most this low


@njit(cache=True, fastmath=_FASTMATH, error_model="numpy")
def body_significance(m1x, m1y, m2x, m2y, thr1, thr2, mags):
    """mags rows: |moment| of both columns and the larger |moment| / threshold of every body."""
    inv1 = 1.0 / thr1 if thr1 > 0 else 0.0
    inv2 = 1.0 / thr2 if thr2 > 0 else 0.0
    for j in range(m1x.shape[0]):
        mags[0, j] = np.sqrt(m1x[j] * m1x[j] + m1y[j] * m1y[j])
        mags[1, j] = np.sqrt(m2x[j] * m2x[j] + m2y[j] * m2y[j])
        mags[2, j] = max(mags[0, j] * inv1, mags[1, j] * inv2)  # a conservative significance


@njit(cache=True, fastmath=_FASTMATH, error_model="numpy")
def source_geometry(a, ax, ay, bx, by, sig, img, r, geo):
    """Position, unit-moment bound 2 w / (D - r)^3 and D^2 of every body image seen from agent ``a``.

    Column k = i * bodies + j of ``geo``; branch-free over bodies so it
    vectorises. ``G_LS`` receives bound / threshold (``sig``: a body's larger
    |moment| / threshold), ``G_LX`` D^2, both > 0 for their log2. The agent's
    own body (the identity image of ``a``) gets bound 0: its own induced moment
    is 0 and its intrinsic dipole enters through its images only.
    """
    nb = bx.shape[0]
    for i in range(img.shape[0]):
        ox, sx, oy, sy, w = img[i, 0], img[i, 1], img[i, 2], img[i, 3], img[i, 4]
        for j in range(nb):
            k = i * nb + j
            x = ox + sx * bx[j]
            y = oy + sy * by[j]
            d2 = (x - ax) * (x - ax) + (y - ay) * (y - ay)
            gap = max(np.sqrt(d2) - r, 1e-100)  # a source inside the sensor circle gets a huge bound
            unit = 2.0 * w / (gap * gap * gap) * (k != a)
            geo[G_X, k] = x
            geo[G_Y, k] = y
            geo[G_UNIT, k] = unit
            geo[G_LS, k] = unit * sig[j] + 1e-300
            geo[G_LX, k] = d2 + 1e-300


@njit(cache=True, fastmath=_FASTMATH, error_model="numpy")
def cull_column(a, mag, mx, my, thr, img, unit, out_x, out_y):
    """Image moments of one column, 0 where the bound |m| * unit is below ``thr``; returns the bound sum.

    ``a``'s own body is dropped (see :func:`source_geometry`).
    """
    nb = mag.shape[0]
    total = 0.0  # bounds steer decisions only: float64 whatever the dtype
    for i in range(img.shape[0]):
        w, sx, sy = img[i, 4], img[i, 1], img[i, 3]
        for j in range(nb):
            k = i * nb + j
            b = mag[j] * unit[k]
            total += b
            wk = w * ((mag[j] > 0) & (b >= thr) & (k != a))
            out_x[k] = sx * wk * mx[j]
            out_y[k] = sy * wk * my[j]
    return total


@njit(cache=True, fastmath=_FASTMATH, error_model="numpy")
def stage_sources(a, ax, ay, bx, by, m1x, m1y, m2x, m2y, mags, img, r, thr1, thr2, geo):
    """Every body image seen from agent ``a``: position, culled moments and bounds, in ``geo``.

    A column whose bound is below its threshold is stored as 0 (culled);
    ``G_KEEP`` is 1 where any column survives. Separate passes, each over few
    arrays: one loop writing every row would need more runtime alias checks
    than LLVM allows, and would stay scalar. Returns the bound sums of both columns.
    """
    nb = bx.shape[0]
    n = nb * img.shape[0]
    source_geometry(a, ax, ay, bx, by, mags[2, :nb], img, r, geo)
    total1 = cull_column(a, mags[0, :nb], m1x, m1y, thr1, img, geo[G_UNIT], geo[G_M1X], geo[G_M1Y])
    total2 = cull_column(a, mags[1, :nb], m2x, m2y, thr2, img, geo[G_UNIT], geo[G_M2X], geo[G_M2Y])
    for k in range(n):
        geo[G_KEEP, k] = (geo[G_M1X, k] != 0) | (geo[G_M1Y, k] != 0) | (geo[G_M2X, k] != 0) | (geo[G_M2Y, k] != 0)
    return total1, total2


@njit(cache=True, fastmath=_FASTMATH, error_model="numpy")
def log2_upper(values, out):
    """out >= log2(values) within 0.09, from the float bit pattern (Mitchell); vectorises, no libm call."""
    bits = values.view(np.int64)
    for k in range(values.shape[0]):
        out[k] = bits[k] * 2.0 ** -52 - 1023.0 + MITCHELL_ERROR


@njit(cache=True, fastmath=_FASTMATH, error_model="numpy")
def dense_level_sources(n, geo, level_lcq, level_e, c, dense):
    """dense[k] = 1 where source k is served by the first far level, else 0.

    The bound of level l is C Q_l B x^(e_l); in log2 the condition is
    log2(C Q_l) + ls + e_l lx <= 0, with upper bounds ``ls`` >= log2(bound /
    threshold) and lx >= log2(r / D), written over ``geo`` rows G_LS and G_LX,
    so the choice errs towards accuracy. A source is never interpolated when it
    is closer than the far-field minimum, or so strong (bound / threshold >
    2^FAR_MAX_LS) that float32, in which interpolated sources are evaluated,
    would round off more than the threshold. Branch-free, so it vectorises.
    """
    ls, lx = geo[G_LS, :n], geo[G_LX, :n]
    log2_upper(ls, ls)
    log2_upper(lx, lx)
    log2_r = math.log2(c[R_SENS])
    lcq, e = level_lcq[0], level_e[0]
    for k in range(n):
        lx[k] = log2_r - 0.5 * (lx[k] - MITCHELL_ERROR)
        near = (lx[k] > c[FAR_MAX_LX]) | (ls[k] > c[FAR_MAX_LS])
        dense[k] = (lcq + ls[k] + e * lx[k] <= 0) & (near == 0)


@njit(cache=True, error_model="numpy")
def source_level(ls, lx, level_lcq, level_e, c):
    """Bucket of a source that the first level does not serve: 1 + its level, or 0 (exact)."""
    if (lx > c[FAR_MAX_LX]) | (ls > c[FAR_MAX_LS]):
        return 0
    for lv in range(1, level_e.shape[0]):
        if level_lcq[lv] + ls + level_e[lv] * lx <= 0:
            return lv + 1
    return 0


@njit(cache=True, fastmath=_FASTMATH, error_model="numpy")
def gather_sources(a, ax, ay, bx, by, m1x, m1y, m2x, m2y, img, c, thr1, thr2, level_lcq, level_e,
                   mags, geo, in_dense, order, level, dense, exact, far, offsets):
    """Images of body moments whose bound at agent ``a`` reaches a threshold, bucketed by level.

    Column 1 (Mormyromast) and column 2 (Ampullary) are culled separately; a
    culled column is stored as 0. Sources of the first far level (most of them)
    go to ``dense`` (float32, positions relative to the agent, where float32 is
    precise), every source in its own column with the others' moments zeroed:
    one long loop over sources evaluates them. Only the rest, a few tens, are
    bucketed: bucket l holds sources ``offsets[l]:offsets[l + 1]``, the exact
    ones (bucket 0) in ``exact`` in the working dtype, those of the higher
    levels in the same columns of ``far`` in float32 (bucket 1, the dense
    level, stays empty). Every bucket is padded with inert sources (moment 0,
    1 m away) to a multiple of ``EXACT_BLOCK`` (bucket 0) or ``BLOCK``, so its
    loops run without a scalar remainder. Returns the number of dense columns
    (0 without far levels) and the bound sums of both columns.
    """
    n = bx.shape[0] * img.shape[0]
    body_significance(m1x, m1y, m2x, m2y, thr1, thr2, mags)
    total1, total2 = stage_sources(a, ax, ay, bx, by, m1x, m1y, m2x, m2y, mags, img, c[R_SENS], thr1, thr2, geo)
    n_levels = level_e.shape[0]
    if n_levels > 0:
        dense_level_sources(n, geo, level_lcq, level_e, c, in_dense)
    else:
        in_dense[:n] = False
    n_dense = -(-n // BLOCK) * BLOCK if n_levels > 0 else 0
    for k in range(n):  # branch-free, so it vectorises
        d = in_dense[k]
        dense[SX, k], dense[SY, k] = geo[G_X, k] - ax, geo[G_Y, k] - ay
        dense[M1X, k], dense[M1Y, k] = geo[G_M1X, k] * d, geo[G_M1Y, k] * d
        dense[M2X, k], dense[M2Y, k] = geo[G_M2X, k] * d, geo[G_M2Y, k] * d
    for k in range(n, n_dense):
        dense[SX, k], dense[SY, k] = 1.0, 0.0
        dense[M1X, k] = dense[M1Y, k] = dense[M2X, k] = dense[M2Y, k] = 0.0
    rest = 0
    for k in range(n):  # branch-free compaction of the others (its own loop: the one above vectorises)
        order[rest] = k
        rest += (geo[G_KEEP, k] != 0) & (in_dense[k] == 0)
    # counting sort of the others by bucket, each bucket padded to whole blocks
    offsets[:] = 0
    for t in range(rest):
        k = order[t]
        level[t] = source_level(geo[G_LS, k], geo[G_LX, k], level_lcq, level_e, c) if n_levels > 0 else 0
        offsets[level[t] + 1] += 1
    for lv in range(offsets.shape[0] - 1):
        block = EXACT_BLOCK if lv == 0 else BLOCK
        offsets[lv + 1] = offsets[lv] + -(-offsets[lv + 1] // block) * block
    fill = offsets[:-1].copy()
    for t in range(rest):
        k, lv = order[t], level[t]
        q = fill[lv]
        fill[lv] += 1
        if lv == 0:
            exact[SX, q], exact[SY, q] = geo[G_X, k], geo[G_Y, k]
            exact[M1X, q], exact[M1Y, q] = geo[G_M1X, k], geo[G_M1Y, k]
            exact[M2X, q], exact[M2Y, q] = geo[G_M2X, k], geo[G_M2Y, k]
        else:
            far[SX, q], far[SY, q] = geo[G_X, k] - ax, geo[G_Y, k] - ay
            far[M1X, q], far[M1Y, q] = geo[G_M1X, k], geo[G_M1Y, k]
            far[M2X, q], far[M2Y, q] = geo[G_M2X, k], geo[G_M2Y, k]
    for q in range(fill[0], offsets[1]):
        exact[SX, q], exact[SY, q] = ax + 1.0, ay
        exact[M1X, q] = exact[M1Y, q] = exact[M2X, q] = exact[M2Y, q] = 0.0
    for lv in range(1, offsets.shape[0] - 1):
        for q in range(fill[lv], offsets[lv + 1]):
            far[SX, q], far[SY, q] = 1.0, 0.0
            far[M1X, q] = far[M1Y, q] = far[M2X, q] = far[M2Y, q] = 0.0
    return n_dense, total1, total2


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
    """Add the dipoles of column (col_x, col_y) of ``src[:count]`` at every sensor.

    Sources innermost (a padded bucket: no scalar remainder), summed in registers.
    """
    one, three, soft2 = c[ONE], c[THREE], c[SOFT2]
    x, y, mx, my = src[SX, :count], src[SY, :count], src[col_x, :count], src[col_y, :count]
    for s in range(out.shape[0]):
        acc = c[ZERO]
        for i in range(x.shape[0]):
            dx = sx[s] - x[i]
            dy = sy[s] - y[i]
            inv_r2 = one / (dx * dx + dy * dy + soft2)
            inv_r3 = inv_r2 * np.sqrt(inv_r2)
            acc += inv_r3 * (three * (mx[i] * dx + my[i] * dy) * (dx * nx[s] + dy * ny[s]) * inv_r2
                             - (mx[i] * nx[s] + my[i] * ny[s]))
        out[s] += acc


@njit(cache=True, fastmath=_FASTMATH, error_model="numpy")
def interpolate_add(out, matrix, values, lo, hi):
    """out += matrix[lo:hi].T @ values[lo:hi]: trigonometric interpolation from one level's points to the sensors.

    ``matrix`` is (points, sensors): each point adds its value times one
    contiguous row to all sensors at once (levels hold few points, classes many sensors).
    """
    for q in range(lo, hi):
        row, v = matrix[q], values[q]
        for s in range(out.shape[0]):
            out[s] += row[s] * v


@njit(cache=True, fastmath=_FASTMATH, error_model="numpy")
def sense_agent(a, axy, heading, emitting, bx, by, m1x, m1y, m2x, m2y, img, c, c32, flags, tables, levels,
                level_lcq, level_e, far_offsets, far_points, interp_m, interp_a, mags, geo, in_dense, order, level,
                dense, exact, far, offsets, scratch, scratch32, out_m, out_a):
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
    n_dense, tot1, tot2 = gather_sources(a, ax, ay, bx, by, m1x, m1y, m2x, m2y, img, c, thr1, thr2, level_lcq,
                                         level_e, mags, geo, in_dense, order, level, dense, exact, far, offsets)
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
    if not (do_m or do_a) or (offsets[-1] == offsets[1] and n_dense == 0):
        return
    # the points of every level at once: one cos/sin of the heading per agent
    n_pts = far_offsets[-1]
    px, py, pnx, pny = scratch32[0, :n_pts], scratch32[1, :n_pts], scratch32[2, :n_pts], scratch32[3, :n_pts]
    place_on_circle(np.float32(0.0), np.float32(0.0), np.float32(np.cos(heading[a])), np.float32(np.sin(heading[a])),
                    far_points[0], far_points[1], c32[R_SENS], px, py, pnx, pny)
    for lv in range(levels.shape[0]):
        lo, hi = far_offsets[lv], far_offsets[lv + 1]
        # interpolated sources are evaluated in float32 (twice the SIMD width, far
        # cheaper sqrt and division); positions relative to the agent keep it precise
        if lv == 0:
            far_readings(dense, 0, n_dense, px[lo:hi], py[lo:hi], pnx[lo:hi], pny[lo:hi], c32,
                         scratch32[4, lo:hi], scratch32[5, lo:hi])
        elif offsets[lv + 2] > offsets[lv + 1]:
            far_readings(far, offsets[lv + 1], offsets[lv + 2], px[lo:hi], py[lo:hi], pnx[lo:hi], pny[lo:hi], c32,
                         scratch32[4, lo:hi], scratch32[5, lo:hi])
        else:
            continue  # an empty level adds nothing
        scratch[4, lo:hi] = scratch32[4, lo:hi]
        scratch[5, lo:hi] = scratch32[5, lo:hi]
        if do_m:
            interpolate_add(out_m, interp_m, scratch[4], lo, hi)
        if do_a:
            interpolate_add(out_a, interp_a, scratch[5], lo, hi)


@njit(cache=True, error_model="numpy")
def sense_batch_kernel(agent_xy, heading, emitting, pellet_xy, pellet_phi, pellet_alive, width, height,
                       img_idx, img_w, c, flags, tables, levels, level_lcq, level_e, far_offsets, far_points,
                       interp_m, interp_a, cos_k, sin_k,
                       out_m, out_a, out_k):
    """Raw readings for B arenas. Positions in m, in the dtype of ``c``; outputs zeroed by the caller.

    Bodies are the agents (first N), then the live pellets of each arena, then inert padding.
    """
    b_count, n = agent_xy.shape[0], agent_xy.shape[1]
    nb_max = n + (pellet_xy.shape[1] if flags[DO_PELLETS] else 0)
    nb_max = -(-nb_max // BLOCK) * BLOCK  # room for the inert padding bodies
    cap = nb_max * img_idx.shape[0]
    padded = cap + BLOCK * (levels.shape[0] + 1)  # room for every bucket's padding
    exact = np.empty((N_SRC, padded), c.dtype)
    far = np.empty((N_SRC, padded), np.float32)
    offsets = np.zeros(levels.shape[0] + 2, np.int64)  # bucket l: sources offsets[l]:offsets[l + 1]
    c32 = c.astype(np.float32)
    geo = np.empty((N_GEO, cap), np.float64)
    mags = np.empty((3, nb_max), np.float64)
    in_dense = np.zeros(cap, np.bool_)
    order = np.zeros(cap, np.int64)
    level = np.zeros(cap, np.int64)
    dense = np.empty((N_SRC, padded), np.float32)
    scratch = np.empty((6, max(tables.shape[1], far_points.shape[1])), c.dtype)
    scratch32 = np.empty((6, far_points.shape[1]), np.float32)
    p_ind = np.zeros((n, 2, nb_max), c.dtype)  # per emitter: induced moments of every body
    body = np.empty((7, nb_max), c.dtype)  # x, y, alpha, m1x, m1y, m2x, m2y
    # sin and cos of every heading and pellet orientation, vectorised (libm's are scalar calls)
    angles = np.empty(n + pellet_xy.shape[1])
    sin_t, cos_t = np.empty_like(angles), np.empty_like(angles)
    for b in range(b_count):
        img = image_table(width[b], height[b], img_idx, img_w, c)
        if flags[DO_AMP]:
            angles[:n] = heading[b]
            angles[n:] = pellet_phi[b]
            sincos(angles, sin_t, cos_t)
        nb = 0
        for j in range(n):
            body[0, nb], body[1, nb], body[2, nb] = agent_xy[b, j, 0], agent_xy[b, j, 1], c[ALPHA_AGENT]
            body[5, nb] = c[K] * c[P_AGENT] * cos_t[j] if flags[DO_AMP] else c[ZERO]
            body[6, nb] = c[K] * c[P_AGENT] * sin_t[j] if flags[DO_AMP] else c[ZERO]
            nb += 1
        for j in range(pellet_xy.shape[1] if flags[DO_PELLETS] else 0):
            if pellet_alive[b, j]:
                body[0, nb], body[1, nb], body[2, nb] = pellet_xy[b, j, 0], pellet_xy[b, j, 1], c[ALPHA_PELLET]
                body[5, nb] = -c[K] * c[P_PELLET] * sin_t[n + j] if flags[DO_AMP] else c[ZERO]
                body[6, nb] = c[K] * c[P_PELLET] * cos_t[n + j] if flags[DO_AMP] else c[ZERO]
                nb += 1
        # pad to whole SIMD blocks with inert bodies (no polarisability, no moment, 100 m away):
        # every loop over bodies then runs without a scalar remainder
        for j in range(nb, -(-nb // BLOCK) * BLOCK):
            body[0, j], body[1, j] = 100.0, 100.0
            body[2:, j] = c[ZERO]
        nb = -(-nb // BLOCK) * BLOCK
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
                        interp_m, interp_a, mags, geo, in_dense, order, level, dense, exact, far, offsets, scratch, scratch32,
                        out_m[b, a], out_a[b, a])
        if flags[DO_KNOLL]:
            knollenorgan_env(agent_xy[b], heading[b], emitting[b], cos_k, sin_k, c, flags, out_k[b])
