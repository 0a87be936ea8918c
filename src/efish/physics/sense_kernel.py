"""Per-agent assembly of raw readings in numba: exact and interpolated sources, Knollenorgans.

Sources (every body and its wall images) carry two moment columns, the
combined Mormyromast moment and the intrinsic (Ampullary) moment; which are
culled, shared between agents or evaluated exactly is decided in
:mod:`efish.physics.sources` by the bound of :mod:`efish.physics.plan`.

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

import numpy as np

from .._jit import njit
from .geometry import slot_agent
from .kernels import (
    _FASTMATH,
    ALPHA_AGENT,
    ALPHA_PELLET,
    CULL,
    DO_AMP,
    DO_INDUCTION,
    DO_KNOLL,
    DO_MORM,
    DO_PELLETS,
    DO_WALLDIST,
    G_CONS,
    G_SELF,
    HALF_SEP,
    K_CONS,
    KNOLL_ZERO,
    M1X,
    M1Y,
    M2X,
    M2Y,
    N_SRC,
    ONE,
    P_AGENT,
    P_PELLET,
    R_SENS,
    SOFT2,
    SX,
    SY,
    THREE,
    TOL_AMP,
    TOL_MORM,
    ZERO,
    ZERO_AMP,
    ZERO_MORM,
    K,
    Q,
    add_monopole,
    far_readings,
    image_table,
    induced_dipoles,
    place_on_circle,
    place_sensors,
)
from .sources import (
    BLOCK,
    L_A1,
    L_T1X,
    L_T1Y,
    N_GEO,
    N_LIST,
    N_SHARED,
    copy_shared,
    gather_sources,
    image_rows,
    imaged_moments,
    list_images,
    share_far_sources,
    weighted_moments,
)
from .trig import sincos


@njit(cache=True)
def mormyromast_weights(a, emitting, c):
    """(w_self, w_cons): weights of the self and cons induced moments in agent ``a``'s Mormyromast moment
    (k folded in); cons carries k_cons when ``a`` is silent or g_self = 0 (SPEC 3.1)."""
    gain = c[K_CONS] if (not emitting[a] or c[G_SELF] == 0) else c[ONE]
    return c[G_SELF] * c[K], c[G_CONS] * gain * c[K]


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
    w_self, w_cons = mormyromast_weights(a, emitting, c)
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
        for slot in range(n - 1):
            j = slot_agent(a, slot)
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
def sense_agent(a, axy, heading, emitting, n_list, lst, own, n_shared, shared_tot, img, c, c32, flags, tables,
                levels, level_lcq, level_e, far_offsets, far_points, interp_m, interp_a, geo, in_dense, order, dense,
                exact, far, offsets, scratch, scratch32, out_m, out_a):
    """Mormyromast and Ampullary raw readings of agent ``a``.

    The first ``n_list`` columns of ``lst`` and ``own`` list the sources that
    are not shared, with ``a``'s Mormyromast moments in ``geo`` (see
    :func:`efish.physics.sources.gather_sources`); ``dense[:, :n_shared]``
    holds the shared ones as ``a`` evaluates them, ``shared_tot`` their bound
    sums in both columns.
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
    n_dense, tot1, tot2 = gather_sources(a, n_list, ax, ay, lst, own, thr1, thr2, c, level_lcq, level_e, n_shared,
                                         geo, in_dense, order, dense, exact, far, offsets)
    tot1 += shared_tot[0]
    tot2 += shared_tot[1]
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

    Bodies are the agents (first N), then the live pellets of each arena, then
    inert padding. Their images are listed once per arena; when every agent
    weighs self and cons induced moments alike (g_self = g_cons), the pellet
    images far from every agent are shared by all agents
    (:func:`efish.physics.sources.share_far_sources`).
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
    lst, rest = np.empty((N_LIST, cap), np.float64), np.empty((N_LIST, cap), np.float64)
    own, owner = np.empty(cap, np.int64), np.empty(cap, np.int64)
    rest_own, rest_owner = np.empty(cap, np.int64), np.empty(cap, np.int64)
    shared = np.empty((N_SHARED, cap), np.float64)
    shared_tot = np.zeros(2)
    geo = np.empty((N_GEO, cap), np.float64)
    in_dense = np.zeros(cap, np.bool_)
    order = np.zeros(2 * cap, np.int64)  # bucket of each listed source, then a bucket's members
    dense = np.empty((N_SRC, padded), np.float32)
    scratch = np.empty((6, max(tables.shape[1], far_points.shape[1])), c.dtype)
    scratch32 = np.empty((6, far_points.shape[1]), np.float32)
    p_ind = np.zeros((n, 2, nb_max), c.dtype)  # per emitter: induced moments of every body
    body = np.empty((9, nb_max), c.dtype)  # x, y, alpha, m1x, m1y, m2x, m2y, t1x, t1y
    # sin and cos of every heading and pellet orientation, vectorised (libm's are scalar calls)
    angles = np.empty(n + pellet_xy.shape[1])
    sin_t, cos_t = np.empty_like(angles), np.empty_like(angles)
    share = levels.shape[0] > 0 and flags[CULL] and c[G_SELF] == c[G_CONS]
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
        n_src = nb * img.shape[0]
        induction = False
        if flags[DO_INDUCTION]:
            for e in range(n):
                induction = induction or emitting[b, e]
        if induction:
            induced_dipoles(agent_xy[b], heading[b], emitting[b], body[0, :nb], body[1, :nb], body[2, :nb], img, c,
                            p_ind)
        # T1: every emitter's induced moment, which each agent weighs alike in shared mode
        t1x, t1y = body[7, :nb], body[8, :nb]
        t1x[:] = c[ZERO]
        t1y[:] = c[ZERO]
        s_max = 0.0  # the largest Mormyromast weight of any agent
        if share and flags[DO_MORM] and induction:
            for e in range(n):
                t1x += p_ind[e, 0, :nb]
                t1y += p_ind[e, 1, :nb]
            for a in range(n):
                s_max = max(s_max, abs(mormyromast_weights(a, emitting[b], c)[1]))
        list_images(body[0, :nb], body[1, :nb], body[5, :nb], body[6, :nb], img, n, lst, own, owner)
        src, src_own, n_list, n_shared = lst, own, n_src, 0
        shared_tot[:] = 0.0
        shared_mode = share and (flags[DO_MORM] or flags[DO_AMP])
        if shared_mode:
            image_rows(img, t1x, t1y, lst[L_T1X], lst[L_T1Y], lst[L_A1])
            n_shared, n_list, shared_tot[0], shared_tot[1] = share_far_sources(
                n_src, agent_xy[b], lst, own, owner, s_max, c[TOL_MORM], c[TOL_AMP], c, level_lcq, level_e, geo,
                in_dense, order, shared, rest, rest_own, rest_owner)
            src, src_own = rest, rest_own
        for a in range(n if (flags[DO_MORM] or flags[DO_AMP]) else 0):
            weight = mormyromast_weights(a, emitting[b], c)[1] if (flags[DO_MORM] and induction) else 0.0
            if shared_mode:  # the agent's Mormyromast moments are weight x T1
                copy_shared(agent_xy[b, a, 0], agent_xy[b, a, 1], weight, shared, n_shared, dense)
                weighted_moments(a, n_list, weight, rest, rest_owner, geo)
            else:  # the full list, with the agent's own moments of every body
                if flags[DO_MORM] and induction:
                    mormyromast_moments(a, emitting[b], p_ind, c, body[3, :nb], body[4, :nb])
                else:
                    body[3, :nb] = c[ZERO]
                    body[4, :nb] = c[ZERO]
                imaged_moments(img, body[3, :nb], body[4, :nb], geo)
            sense_agent(a, agent_xy[b], heading[b], emitting[b], n_list, src, src_own, n_shared, shared_tot, img, c,
                        c32, flags, tables, levels, level_lcq, level_e, far_offsets, far_points, interp_m, interp_a,
                        geo, in_dense, order, dense, exact, far, offsets, scratch, scratch32,
                        out_m[b, a], out_a[b, a])
        if flags[DO_KNOLL]:
            knollenorgan_env(agent_xy[b], heading[b], emitting[b], cos_k, sin_k, c, flags, out_k[b])
