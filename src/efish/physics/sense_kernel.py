"""Per-batch and per-agent assembly of raw readings in numba: exact and interpolated sources, Knollenorgans.

:func:`sense_batch_kernel` names its inputs and runs :func:`sense_arenas`: per
arena :func:`fill_bodies` (agents, live pellets, padding), in shared mode the
pellets every agent culls dropped (:func:`drop_culled_bodies`), the induced
moments and their sum T1 (:func:`t1_moments`), the source list (far pellet images shared
between agents by :func:`efish.physics.sources.share_far_sources`) and
:func:`knollenorgan_env`; per agent the agent's Mormyromast moments and
:func:`sense_agent` (culling and bucketing in
:func:`efish.physics.sources.gather_sources`, then exact and interpolated
readings). Inputs and scratch arrays are the named tuples of
:mod:`efish.physics.kernel_inputs` (shapes there; ``DT`` is the working dtype).
A kernel that calls others counts a reference (an atomic operation) for every
array of every tuple it is passed and every field it reads, so kernels called
per arena or per agent take only the parts they use, and the arena steps are
written out in :func:`sense_arenas` rather than in helpers of their own.

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
from .kernel_inputs import Arena, BatchArrays, Bodies, Lists, Outputs, PlanTables, SourceList, Staging, Workspace
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
    ERROR_BOUND,
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

# Rows of the arena's body table ``Bodies.body``: position, polarisability, the agent's
# Mormyromast moment (full list), the Ampullary moment, T1 (shared mode).
B_X, B_Y, B_ALPHA, B_M1X, B_M1Y, B_M2X, B_M2Y, B_T1X, B_T1Y, N_BODY = range(10)


@njit(cache=True)
def mormyromast_weights(a, emitting, c):
    """(w_self, w_cons): weights of the self and cons induced moments in agent ``a``'s Mormyromast moment
    (k folded in); cons carries k_cons when ``a`` is silent or g_self = 0 (docs/model/sensors.md#mormyromasts)."""
    gain = c[K_CONS] if (not emitting[a] or c[G_SELF] == 0) else c[ONE]
    return c[G_SELF] * c[K], c[G_CONS] * gain * c[K]


@njit(cache=True, fastmath=_FASTMATH, error_model="numpy")
def mormyromast_moments(a, emitting, p_ind, c, mx, my):
    """g_self * self + g_cons * gain * cons moment of every body for agent ``a`` (k folded in).

    self = p_ind[a] (zero when a is silent), cons = sum of p_ind[e] over the
    other emitters; gain = k_cons when ``a`` is silent or g_self = 0 (docs/model/sensors.md#mormyromasts).
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
    (they are part of the self image, docs/model/sensors.md#mormyromasts)."""
    ux = c[HALF_SEP] * np.cos(heading)
    uy = c[HALF_SEP] * np.sin(heading)
    for i in range(1, img.shape[0]):
        for sign in (c[ONE], -c[ONE]):
            px = img[i, 0] + img[i, 1] * (xy[0] + sign * ux)
            py = img[i, 2] + img[i, 3] * (xy[1] + sign * uy)
            add_monopole(out, sx, sy, nx, ny, px, py, sign * c[G_SELF] * c[K] * c[Q] * img[i, 4], c[SOFT2], c[ONE])


@njit(cache=True, fastmath=_FASTMATH, error_model="numpy")
def knollenorgan_env(arena, c, cull, cos_k, sin_k, out):
    """out[a, slot] (DT[N, N - 1, S_k]) = direct EOD field of the slot's conspecific at a's sensors, no images.

    ``cos_k``, ``sin_k`` (DT[S_k]): the sensor angles; ``cull``: skip pairs whose
    every spike would be 0 after binarisation.
    """
    axy, heading, emitting = arena.axy, arena.heading, arena.emitting
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
            if cull and gap > 0 and 4.0 * kq * c[HALF_SEP] / gap ** 3 <= c[KNOLL_ZERO]:
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
def sense_agent(a, arena, srcs, plan, stage, out_m, out_a, out_err):
    """Mormyromast (out_m, DT[S_m]) and Ampullary (out_a, DT[S_a]) raw readings of agent ``a`` of ``arena``,
    and in ``out_err`` (float64[2]) a bound of their error per reading: the bounds of every culled source
    plus the interpolation error bounds (the whole bound sum for a class skipped as exactly zero).

    ``srcs`` lists the sources that are not shared, with ``a``'s Mormyromast
    moments in ``stage.geo``; :func:`~efish.physics.sources.gather_sources`
    stages them, after the shared ones in ``stage.dense[:, :srcs.n_shared]``. A
    class whose bound sum shows that every normalised reading would be 0 is
    skipped. Exact sources are added at the sensors (``stage.sensors`` rows 0-3:
    x, y, nx, ny), the others read at their level's points (``stage.points32``)
    and interpolated; level l owns points ``plan.far_offsets[l]`` up to ``[l + 1]``.
    """
    c, flags, trig = plan.c, plan.flags, plan.sensor_trig
    sens, pts, offsets = stage.sensors, stage.points32, stage.offsets
    sm, sa = out_m.shape[0], out_a.shape[0]
    ax, ay, heading = arena.axy[a, 0], arena.axy[a, 1], arena.heading[a]
    thr1 = c[TOL_MORM] if flags[CULL] else -1.0
    thr2 = c[TOL_AMP] if flags[CULL] else -1.0
    n_dense, tot1, tot2, err1, err2 = gather_sources(a, ax, ay, thr1, thr2, srcs, c, plan.level_lcq, plan.level_e,
                                                     stage, flags[ERROR_BOUND])
    tot1 += srcs.bound_m  # plus the shared sources' bounds and errors
    tot2 += srcs.bound_a
    err1 += srcs.error_m
    err2 += srcs.error_a
    walls = flags[DO_WALLDIST] and arena.emitting[a] and arena.img.shape[0] > 1 and c[G_SELF] != 0
    do_m = flags[DO_MORM] and (walls or not flags[CULL] or tot1 > c[ZERO_MORM])
    do_a = flags[DO_AMP] and (not flags[CULL] or tot2 > c[ZERO_AMP])
    if flags[ERROR_BOUND]:
        out_err[0] = (err1 if do_m else tot1) if flags[DO_MORM] else 0.0
        out_err[1] = (err2 if do_a else tot2) if flags[DO_AMP] else 0.0
    sx, sy, nx, ny = sens[0], sens[1], sens[2], sens[3]
    if do_m:
        place_sensors(ax, ay, heading, trig[0, :sm], trig[1, :sm], c[R_SENS], sx[:sm], sy[:sm], nx[:sm], ny[:sm])
        add_sources(out_m, stage.exact, offsets[1], M1X, M1Y, sx[:sm], sy[:sm], nx[:sm], ny[:sm], c)
        if walls:
            own_eod_images(out_m, arena.axy[a], heading, arena.img, c, sx[:sm], sy[:sm], nx[:sm], ny[:sm])
    if do_a:
        place_sensors(ax, ay, heading, trig[2, :sa], trig[3, :sa], c[R_SENS], sx[:sa], sy[:sa], nx[:sa], ny[:sa])
        add_sources(out_a, stage.exact, offsets[1], M2X, M2Y, sx[:sa], sy[:sa], nx[:sa], ny[:sa], c)
    if not (do_m or do_a) or (offsets[-1] == offsets[1] and n_dense == 0):
        return
    # the points of every level at once: one cos/sin of the heading per agent
    c32, far_offsets, dense, far, interp_m, interp_a = (plan.c32, plan.far_offsets, stage.dense, stage.far,
                                                       plan.interp_m, plan.interp_a)
    n_pts = far_offsets[-1]
    px, py, pnx, pny = pts[0, :n_pts], pts[1, :n_pts], pts[2, :n_pts], pts[3, :n_pts]
    place_on_circle(np.float32(0.0), np.float32(0.0), np.float32(np.cos(heading)), np.float32(np.sin(heading)),
                    plan.far_points[0], plan.far_points[1], c32[R_SENS], px, py, pnx, pny)
    for lv in range(plan.levels.shape[0]):
        lo, hi = far_offsets[lv], far_offsets[lv + 1]
        # interpolated sources are evaluated in float32 (twice the SIMD width, far
        # cheaper sqrt and division); positions relative to the agent keep it precise
        if lv == 0:
            far_readings(dense, 0, n_dense, px[lo:hi], py[lo:hi], pnx[lo:hi], pny[lo:hi], c32, pts[4, lo:hi],
                         pts[5, lo:hi])
        elif offsets[lv + 2] > offsets[lv + 1]:
            far_readings(far, offsets[lv + 1], offsets[lv + 2], px[lo:hi], py[lo:hi], pnx[lo:hi], pny[lo:hi], c32,
                         pts[4, lo:hi], pts[5, lo:hi])
        else:
            continue  # an empty level adds nothing
        sens[4, lo:hi] = pts[4, lo:hi]
        sens[5, lo:hi] = pts[5, lo:hi]
        if do_m:
            interpolate_add(out_m, interp_m, sens[4], lo, hi)
        if do_a:
            interpolate_add(out_a, interp_a, sens[5], lo, hi)


@njit(cache=True, error_model="numpy")
def make_workspace(batch, plan):
    """The scratch arrays of one call (:class:`~efish.physics.kernel_inputs.Workspace`), sized for the fullest arena."""
    c, n, n_pel = plan.c, batch.agent_xy.shape[1], batch.pellet_xy.shape[1]
    nb_max = n + (n_pel if plan.flags[DO_PELLETS] else 0)
    nb_max = -(-nb_max // BLOCK) * BLOCK  # room for the inert padding bodies
    cap = nb_max * plan.img_idx.shape[0]
    padded = cap + BLOCK * (plan.levels.shape[0] + 1)  # room for every bucket's padding
    n_pts = plan.far_points.shape[1]
    angles = np.empty(n + n_pel)
    bodies = Bodies(body=np.empty((N_BODY, nb_max), c.dtype), p_ind=np.zeros((n, 2, nb_max), c.dtype),
                    angles=angles, sin_t=np.empty_like(angles), cos_t=np.empty_like(angles))
    lists = Lists(lst=np.empty((N_LIST, cap), np.float64), own=np.empty(cap, np.int64),
                  owner=np.empty(cap, np.int64), rest=np.empty((N_LIST, cap), np.float64),
                  rest_own=np.empty(cap, np.int64), rest_owner=np.empty(cap, np.int64),
                  shared=np.empty((N_SHARED, cap), np.float64))
    staging = Staging(
        geo=np.empty((N_GEO, cap), np.float64), in_dense=np.zeros(cap, np.bool_), order=np.zeros(2 * cap, np.int64),
        dense=np.empty((N_SRC, padded), np.float32), exact=np.empty((N_SRC, padded), c.dtype),
        far=np.empty((N_SRC, padded), np.float32), offsets=np.zeros(plan.levels.shape[0] + 2, np.int64),
        sensors=np.empty((6, max(plan.sensor_trig.shape[1], n_pts)), c.dtype),
        points32=np.empty((6, n_pts), np.float32))
    return Workspace(bodies, lists, staging)


@njit(cache=True, error_model="numpy")
def fill_bodies(b, batch, c, flags, bodies):
    """Rows B_X, B_Y, B_ALPHA, B_M2X, B_M2Y of ``bodies.body`` for arena ``b``; returns the body count, padded.

    Bodies are the agents (first N), then the arena's live pellets, then inert
    padding to whole SIMD blocks (no polarisability, no moment, 100 m away), so
    every loop over bodies runs without a scalar remainder. ``bodies.sin_t`` and
    ``cos_t`` hold the sines and cosines of the headings and pellet orientations.
    """
    body, sin_t, cos_t = bodies.body, bodies.sin_t, bodies.cos_t
    n, n_pel = batch.agent_xy.shape[1], batch.pellet_xy.shape[1]
    nb = 0
    for j in range(n):
        body[B_X, nb], body[B_Y, nb] = batch.agent_xy[b, j, 0], batch.agent_xy[b, j, 1]
        body[B_ALPHA, nb] = c[ALPHA_AGENT]
        body[B_M2X, nb] = c[K] * c[P_AGENT] * cos_t[j] if flags[DO_AMP] else c[ZERO]
        body[B_M2Y, nb] = c[K] * c[P_AGENT] * sin_t[j] if flags[DO_AMP] else c[ZERO]
        nb += 1
    for j in range(n_pel if flags[DO_PELLETS] else 0):
        if batch.pellet_alive[b, j]:
            body[B_X, nb], body[B_Y, nb] = batch.pellet_xy[b, j, 0], batch.pellet_xy[b, j, 1]
            body[B_ALPHA, nb] = c[ALPHA_PELLET]
            body[B_M2X, nb] = -c[K] * c[P_PELLET] * sin_t[n + j] if flags[DO_AMP] else c[ZERO]
            body[B_M2Y, nb] = c[K] * c[P_PELLET] * cos_t[n + j] if flags[DO_AMP] else c[ZERO]
            nb += 1
    for j in range(nb, -(-nb // BLOCK) * BLOCK):
        body[B_X, j], body[B_Y, j] = 100.0, 100.0
        body[B_ALPHA:, j] = c[ZERO]
    return -(-nb // BLOCK) * BLOCK


@njit(cache=True, error_model="numpy")
def t1_moments(nb, fill, c, bodies, n):
    """T1, the sum over the ``n`` agents (silent ones induce 0) of the moments induced in the first ``nb`` bodies,
    in rows B_T1X, B_T1Y.

    Every agent weighs T1 alike in shared mode; it is filled there only (``fill``, else 0).
    Loops, not array expressions: a kernel that cannot raise keeps no reference counts.
    """
    body, p_ind = bodies.body, bodies.p_ind
    t1x, t1y = body[B_T1X, :nb], body[B_T1Y, :nb]
    for j in range(nb):
        t1x[j] = c[ZERO]
        t1y[j] = c[ZERO]
    if fill:
        for e in range(n):
            for j in range(nb):
                t1x[j] += p_ind[e, 0, j]
                t1y[j] += p_ind[e, 1, j]


@njit(cache=True, fastmath=_FASTMATH, error_model="numpy")
def drop_culled_bodies(body, n, nb, arena, s_max, c, image_sum, pellet_m2, diagonal):
    """Drop the pellets that every agent culls with all their wall images (shared mode), before their moments are
    induced; returns the new padded body count and the bound sums of what was dropped, Mormyromast and Ampullary.

    Every wall image of a point in the arena is at least as far from every
    point in it as the point itself (images of x sit at -x + 2mW and x + 2mW)
    and weighs at most 1. So the EOD of emitter e (monopoles +-h about its
    centre, at distance D) polarises pellet j by at most
    |alpha_j| x ``image_sum`` x 4 k q h / (D - h)^3, ``image_sum`` being the sum
    of the image weights' magnitudes, identity included; summed over the
    emitters this bounds |T1_j|. A pellet's bound at the nearest agent
    (2 |m| / (D - r)^3, T1 times the largest agent weight ``s_max``) bounds it
    at every agent, and its images' bounds sum to at most ``image_sum`` times
    it. A pellet below both thresholds is dropped, so neither its induction nor
    any later per-source pass touches it or its images. Rows B_X, B_Y, B_ALPHA,
    B_M2X, B_M2Y are compacted (agents stay first) and padded as in
    :func:`fill_bodies`. Every pellet carries the Ampullary moment ``pellet_m2``
    (0 when Ampullary organs are off): when its bound across the arena's
    ``diagonal`` reaches the threshold, no pellet can be dropped and the pass is skipped.
    """
    thr1, thr2, r, h = c[TOL_MORM], c[TOL_AMP], c[R_SENS], c[HALF_SEP]
    far_gap = max(diagonal - r, 1e-100)
    if pellet_m2 * 2.0 / (far_gap * far_gap * far_gap) >= thr2:
        return nb, 0.0, 0.0
    axy, emitting = arena.axy, arena.emitting
    polarise = s_max * image_sum * 4.0 * c[K] * c[Q] * h  # per |alpha| and per 1 / (D - h)^3 of each emitter
    skipped1 = skipped2 = 0.0
    kept = n
    for j in range(n, nb):
        x, y = body[B_X, j], body[B_Y, j]
        d2 = np.inf
        field = 0.0
        for a in range(n):
            da2 = (x - axy[a, 0]) ** 2 + (y - axy[a, 1]) ** 2
            d2 = min(d2, da2)
            if emitting[a] and polarise > 0:
                gap_e = max(np.sqrt(da2) - h, 1e-100)
                field += 1.0 / (gap_e * gap_e * gap_e)
        gap = max(np.sqrt(d2) - r, 1e-100)
        unit = 2.0 / (gap * gap * gap)
        b1 = polarise * abs(np.float64(body[B_ALPHA, j])) * field * unit
        b2 = np.sqrt(np.float64(body[B_M2X, j]) ** 2 + np.float64(body[B_M2Y, j]) ** 2) * unit
        if b1 < thr1 and b2 < thr2:
            skipped1 += b1
            skipped2 += b2
        else:
            for row in (B_X, B_Y, B_ALPHA, B_M2X, B_M2Y):
                body[row, kept] = body[row, j]
            kept += 1
    padded = -(-kept // BLOCK) * BLOCK
    for j in range(kept, padded):
        body[B_X, j], body[B_Y, j] = 100.0, 100.0
        body[B_ALPHA:, j] = c[ZERO]
    return padded, skipped1 * image_sum, skipped2 * image_sum


@njit(cache=True, error_model="numpy")
def largest_cons_weight(emitting, c):
    """The largest magnitude of any agent's cons weight (see :func:`mormyromast_weights`); equals the self weight
    in shared mode, where g_self = g_cons."""
    s_max = 0.0
    for a in range(emitting.shape[0]):
        s_max = max(s_max, abs(mormyromast_weights(a, emitting, c)[1]))
    return s_max


@njit(cache=True, error_model="numpy")
def sense_arenas(batch, plan, ws, out):
    """Add the raw readings of every arena of ``batch`` to ``out``, with the scratch arrays ``ws``.

    Per arena: bodies, induced moments and T1, the source list (in shared mode,
    g_self = g_cons, without the pellets every agent culls and the far pellet
    images every agent reads densely),
    then per agent its Mormyromast moments of the listed sources (``stage.geo``
    rows G_P1X, G_P1Y, G_A1) and its readings. Fields are read once, before the loops.
    """
    c, flags, n, out_m, out_a, out_k = (plan.c, plan.flags, batch.agent_xy.shape[1], out.mormyromast, out.ampullary,
                                        out.knollenorgan)
    out_err = out.error_bound
    agent_xy, heading, emits, pellet_phi = batch.agent_xy, batch.heading, batch.emitting, batch.pellet_phi
    bodies, lists, stage = ws.bodies, ws.lists, ws.staging
    body, p_ind, angles, sin_t, cos_t = bodies.body, bodies.p_ind, bodies.angles, bodies.sin_t, bodies.cos_t
    lst, own, owner, shared, geo, dense = lists.lst, lists.own, lists.owner, lists.shared, stage.geo, stage.dense
    img_idx, img_w, level_lcq, level_e, cos_k, sin_k = (plan.img_idx, plan.img_w, plan.level_lcq, plan.level_e,
                                                       plan.cos_k, plan.sin_k)
    share = plan.levels.shape[0] > 0 and flags[CULL] and c[G_SELF] == c[G_CONS]
    sense = flags[DO_MORM] or flags[DO_AMP]
    pellet_m2 = abs(c[K] * c[P_PELLET]) if flags[DO_AMP] else 0.0
    image_sum = 0.0
    for i in range(img_w.shape[0]):
        image_sum += abs(img_w[i])
    for b in range(agent_xy.shape[0]):
        axy, emitting = agent_xy[b], emits[b]
        img = image_table(batch.width[b], batch.height[b], img_idx, img_w, c)
        arena = Arena(axy, heading[b], emitting, img)
        if flags[DO_AMP]:  # sin and cos of every heading and pellet orientation, vectorised (libm's are scalar calls)
            angles[:n] = heading[b]
            angles[n:] = pellet_phi[b]
            sincos(angles, sin_t, cos_t)
        nb = fill_bodies(b, batch, c, flags, bodies)
        induction = False
        for e in range(n if flags[DO_INDUCTION] else 0):
            induction = induction or emitting[e]
        fill_t1 = share and flags[DO_MORM] and induction
        s_max = largest_cons_weight(emitting, c) if fill_t1 else 0.0
        dropped1 = dropped2 = 0.0
        if share and sense:  # pellets every agent culls leave before their moments are induced
            nb, dropped1, dropped2 = drop_culled_bodies(body, n, nb, arena, s_max, c, image_sum, pellet_m2,
                                                        np.sqrt(batch.width[b] ** 2 + batch.height[b] ** 2))
        if induction:  # every emitter's EOD and its images polarise every body
            induced_dipoles(axy, heading[b], emitting, body[B_X, :nb], body[B_Y, :nb], body[B_ALPHA, :nb], img, c,
                            p_ind)
        t1_moments(nb, fill_t1, c, bodies, n)
        list_images(body[B_X, :nb], body[B_Y, :nb], body[B_M2X, :nb], body[B_M2Y, :nb], img, n, lst, own, owner)
        srcs = SourceList(lst, own, owner, nb * img.shape[0], 0, False, 0.0, 0.0, 0.0, 0.0)  # all sources, per agent
        if share and sense:  # or only those that are not shared
            image_rows(img, body[B_T1X, :nb], body[B_T1Y, :nb], lst[L_T1X], lst[L_T1Y], lst[L_A1])
            srcs = share_far_sources(srcs.n, axy, s_max, c, level_lcq, level_e, lists, stage, flags[ERROR_BOUND],
                                     dropped1, dropped2)
        weighs, srcs_lst, srcs_owner = flags[DO_MORM] and induction, srcs.lst, srcs.owner
        m1x, m1y = body[B_M1X, :nb], body[B_M1Y, :nb]
        for a in range(n if sense else 0):
            weight = mormyromast_weights(a, emitting, c)[1] if weighs else 0.0
            if srcs.shared:  # the agent's Mormyromast moments are weight x T1
                copy_shared(axy[a, 0], axy[a, 1], weight, shared, srcs.n_shared, dense)
                weighted_moments(a, srcs.n, weight, srcs_lst, srcs_owner, geo)
            else:  # the full list, with the agent's own moments of every body
                if weighs:
                    mormyromast_moments(a, emitting, p_ind, c, m1x, m1y)
                else:
                    m1x[:] = c[ZERO]
                    m1y[:] = c[ZERO]
                imaged_moments(img, m1x, m1y, geo)
            sense_agent(a, arena, srcs, plan, stage, out_m[b, a], out_a[b, a], out_err[b, a])
        if flags[DO_KNOLL]:
            knollenorgan_env(arena, c, flags[CULL], cos_k, sin_k, out_k[b])


@njit(cache=True, error_model="numpy")
def sense_batch_kernel(batch_fields, plan_fields, out_fields):
    """Add the raw readings of B arenas to the outputs; positions in m, in the dtype of ``PlanTables.c``.

    The arguments are the fields of a :class:`~efish.physics.kernel_inputs.BatchArrays`,
    a :class:`~efish.physics.kernel_inputs.PlanTables` and an
    :class:`~efish.physics.kernel_inputs.Outputs` (zeroed by the caller) as plain
    tuples, ``tuple(named)``: numba types a plain tuple of arrays in C, a named one
    in Python (about 4 us per call). They are named again here, in the fields' own order.
    :func:`efish.physics.fast.fast_raw` builds them and calls this.
    """
    batch, plan, out = BatchArrays(*batch_fields), PlanTables(*plan_fields), Outputs(*out_fields)
    sense_arenas(batch, plan, make_workspace(batch, plan), out)
