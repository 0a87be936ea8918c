"""Source lists of the fast path (numba): every body image, culled and sorted by how it is evaluated.

Each arena lists its body images once (:func:`list_images`). Seen from an
agent, a source is culled (its bound is below ``tolerance x E_min``), served by
a far-field level (its reading on the sensor circle is smooth enough to carry
from a few points, see :mod:`efish.physics.sense_kernel`) or exact.

Most sources are far from every agent. When every agent weighs the self and
cons induced moments alike (g_self = g_cons, the default), an agent's
Mormyromast moment of a pellet is the same vector times an agent weight, so
those sources are tested once per arena, at the nearest agent with the largest
weight, and shared (:func:`share_far_sources`): every agent evaluates them at
the first level without staging them. Only the rest, about a fifth, is staged
per agent (:func:`gather_sources`).

Loops here are narrow on purpose: a loop over many arrays needs more runtime
alias checks than LLVM allows and stays scalar (3-4x slower), and a per-source
lookup through an index array (a gather) costs as much; so per-source
quantities are laid out in rows and each pass touches few of them.
"""

from __future__ import annotations

import math

import numpy as np

from .._jit import njit
from .kernel_inputs import SourceList
from .kernels import _FASTMATH, FAR_MAX_LS, FAR_MAX_LX, M1X, M1Y, M2X, M2Y, R_SENS, SX, SY, TOL_AMP, TOL_MORM

# Rows of a source list (float64), one column per body image; in the arena's full list
# image i of body j is column i * bodies + j. Moments are image moments (mirrored,
# times the wall weight). T1: the Mormyromast moment per unit of an agent's weight
# (shared mode); M2: the Ampullary moment; A1, A2: their magnitudes.
L_X, L_Y, L_T1X, L_T1Y, L_M2X, L_M2Y, L_A1, L_A2, N_LIST = range(9)
# Rows of the per-agent staging array ``geo`` (float64), one column per listed source.
G_P1X, G_P1Y, G_A1, G_M1X, G_M1Y, G_M2X, G_M2Y, G_LS, G_LX, G_KEEP, G_UNIT, G_D2, N_GEO = range(13)
# Rows of the shared sources (float64): position, T1 and M2 moments.
S_X, S_Y, S_T1X, S_T1Y, S_M2X, S_M2Y, N_SHARED = range(7)
# Sources per SIMD block, measured best: float32 loops over 24 sources take longer than over 32
# (a scalar remainder), float64 loops over sensors x sources pay per 8 sources.
BLOCK = 16
EXACT_BLOCK = 8
MITCHELL_ERROR = 0.0861  # max of log2(1 + f) - f on [0, 1]: the bit-pattern log2 is at most this low
# Round-off of an interpolated source, evaluated in float32, as a fraction of its bound: positions
# relative to the agent (a relative eps on D, about 4 eps on the field), the dipole formula (about 10
# ulp) and the float32 sums over the sources of each SIMD lane (growing like sqrt(count) eps), padded.
F32_ROUNDOFF = 64 * float(np.finfo(np.float32).eps)
NOBODY = -1  # ``own``/``owner`` of a source that is no agent's


@njit(cache=True, fastmath=_FASTMATH, error_model="numpy")
def image_rows(img, vx, vy, out_x, out_y, out_a):
    """Image i of body j at column i * bodies + j: mirrored, weighted (vx, vy) and its magnitude.

    Image 0 is the identity (weight 1), so its magnitudes are the bodies' own and
    every other image's are a weight times them: one square root per body.
    """
    nb = vx.shape[0]
    body_a = out_a[:nb]
    for j in range(nb):
        x, y = np.float64(vx[j]), np.float64(vy[j])  # induced moments squared underflow float32
        body_a[j] = np.sqrt(x * x + y * y)
    for i in range(img.shape[0]):
        fx, fy, w = img[i, 1] * img[i, 4], img[i, 3] * img[i, 4], abs(img[i, 4])
        ox, oy = out_x[i * nb:(i + 1) * nb], out_y[i * nb:(i + 1) * nb]
        for j in range(nb):
            ox[j] = fx * np.float64(vx[j])
            oy[j] = fy * np.float64(vy[j])
        if i > 0:
            oa = out_a[i * nb:(i + 1) * nb]
            for j in range(nb):
                oa[j] = w * body_a[j]


@njit(cache=True, fastmath=_FASTMATH, error_model="numpy")
def list_images(bx, by, m2x, m2y, img, n_agents, lst, own, owner):
    """The arena's full source list: every body image with its Ampullary moment, ``own`` (the agent whose own
    body it is, identity image only) and ``owner`` (the agent whose body it is, every image), NOBODY for pellets.
    The T1 rows are filled by :func:`image_rows` in shared mode only."""
    nb = bx.shape[0]
    for i in range(img.shape[0]):
        ox, sx, oy, sy = img[i, 0], img[i, 1], img[i, 2], img[i, 3]
        x, y = lst[L_X, i * nb:(i + 1) * nb], lst[L_Y, i * nb:(i + 1) * nb]
        for j in range(nb):
            x[j] = ox + sx * bx[j]
            y[j] = oy + sy * by[j]
        for j in range(nb):
            owner[i * nb + j] = j if j < n_agents else NOBODY
            own[i * nb + j] = j if (j < n_agents) & (i == 0) else NOBODY
    image_rows(img, m2x, m2y, lst[L_M2X], lst[L_M2Y], lst[L_A2])


@njit(cache=True, fastmath=_FASTMATH, error_model="numpy")
def distance2(ax, ay, x, y, d2):
    """Squared distance of every listed source from (ax, ay)."""
    for t in range(x.shape[0]):
        d2[t] = (x[t] - ax) * (x[t] - ax) + (y[t] - ay) * (y[t] - ay)


@njit(cache=True, fastmath=_FASTMATH, error_model="numpy")
def nearest_distance2(axy, x, y, d2):
    """Squared distance of every listed source from the nearest agent."""
    d2[:] = np.inf
    for a in range(axy.shape[0]):
        ax, ay = axy[a, 0], axy[a, 1]
        for t in range(x.shape[0]):
            d2[t] = min(d2[t], (x[t] - ax) * (x[t] - ax) + (y[t] - ay) * (y[t] - ay))


@njit(cache=True, fastmath=_FASTMATH, error_model="numpy")
def source_bounds(a, d2, own, a1, a2, inv1, inv2, r, geo):
    """Bound of a unit moment 2 / (D - r)^3 (``G_UNIT``), bound / threshold (``G_LS``) and D^2 (``G_LX``).

    a1, a2: |moment| of both columns; inv1, inv2: 1 / their thresholds. Branch-free,
    so it vectorises; ``G_LS`` and ``G_LX`` stay > 0 for their log2. Agent ``a``'s
    own body (its identity image, ``own == a``) gets bound 0: its own induced moment
    is 0 and its intrinsic dipole enters through its images only.
    """
    unit, ls, lx = geo[G_UNIT, :d2.shape[0]], geo[G_LS, :d2.shape[0]], geo[G_LX, :d2.shape[0]]
    for t in range(d2.shape[0]):
        gap = max(np.sqrt(d2[t]) - r, 1e-100)  # a source inside the sensor circle gets a huge bound
        u = 2.0 / (gap * gap * gap) * (own[t] != a)
        unit[t] = u
        ls[t] = u * max(a1[t] * inv1, a2[t] * inv2) + 1e-300
        lx[t] = d2[t] + 1e-300


@njit(cache=True, fastmath=_FASTMATH, error_model="numpy")
def cull_column(a, mag, mx, my, own, unit, thr, out_x, out_y):
    """One column's moments, 0 where the bound |m| * unit is below ``thr``; returns the bound sums of
    every source and of the culled ones (what culling may have left out of the readings).

    ``a``'s own body is dropped (see :func:`source_bounds`), also when nothing is culled (thr < 0).
    """
    total = skipped = 0.0  # bounds steer decisions only: float64 whatever the dtype
    for t in range(unit.shape[0]):
        b = mag[t] * unit[t]
        total += b
        skipped += b * (b < thr)
        keep = (mag[t] > 0) & (b >= thr) & (own[t] != a)
        out_x[t] = mx[t] * keep
        out_y[t] = my[t] * keep
    return total, skipped


@njit(cache=True, fastmath=_FASTMATH, error_model="numpy")
def level_error(member, d2, unit, a1, a2, keep1, keep2, cq, e, r):
    """Sum over the members of one far level of its error bound, C Q B (r/D)^e plus float32 round-off, per column.

    ``member``, ``keep1``, ``keep2``: nonzero where a source belongs to the level and where its
    column was kept; ``cq`` = C Q and ``e`` the level's order (see :func:`dense_level_sources`).
    """
    err1 = err2 = 0.0
    for k in range(d2.shape[0]):
        x = min(r / np.sqrt(d2[k] + 1e-300), 1.0)  # members are farther than r; others must not overflow
        xe = 1.0
        for _ in range(e):
            xe *= x
        f = (cq * xe + F32_ROUNDOFF) * unit[k] * (member[k] != 0)
        err1 += f * a1[k] * (keep1[k] != 0)
        err2 += f * a2[k] * (keep2[k] != 0)
    return err1, err2


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
    max_lx, max_ls = c[FAR_MAX_LX], c[FAR_MAX_LS]  # locals: LLVM reloads array elements after every store
    for k in range(n):
        lx[k] = log2_r - 0.5 * (lx[k] - MITCHELL_ERROR)
        near = (lx[k] > max_lx) | (ls[k] > max_ls)
        dense[k] = (lcq + ls[k] + e * lx[k] <= 0) & (near == 0)


@njit(cache=True, fastmath=_FASTMATH, error_model="numpy")
def source_buckets(n, geo, in_dense, level_lcq, level_e, c, bucket):
    """bucket[k] of listed source k: -1 when culled or dense, else 0 (exact) or 1 + its far level.

    The level is the lowest (fewest points) whose bound passes; a source too
    close or too strong for float32 is exact (see :func:`dense_level_sources`).
    One branch-free pass per level, so each vectorises.
    """
    ls, lx, keep, b = geo[G_LS, :n], geo[G_LX, :n], geo[G_KEEP, :n], bucket[:n]
    max_lx, max_ls = c[FAR_MAX_LX], c[FAR_MAX_LS]  # locals: LLVM reloads array elements after every store
    b[:] = 0
    for lv in range(level_e.shape[0] - 1, 0, -1):  # highest first: the lowest passing level wins
        lcq, e, value = level_lcq[lv], level_e[lv], lv + 1
        for k in range(n):
            b[k] = value if lcq + ls[k] + e * lx[k] <= 0 else b[k]
    for k in range(n):
        near = (lx[k] > max_lx) | (ls[k] > max_ls)
        b[k] = -1 if (keep[k] == 0) | (in_dense[k] != 0) else (0 if near else b[k])


@njit(cache=True, fastmath=_FASTMATH, error_model="numpy")
def fill_bucket(bucket, lv, x, y, geo, ox, oy, members, out, first):
    """Copy the sources of bucket ``lv`` to ``out`` from column ``first`` on, positions minus (ox, oy).

    The members are listed first (branch-free), then copied: buckets hold a
    few of the listed sources. Returns the column after the last member.
    """
    count = 0
    for k in range(bucket.shape[0]):
        members[count] = k
        count += bucket[k] == lv
    for t in range(count):
        k, q = members[t], first + t
        out[SX, q], out[SY, q] = x[k] - ox, y[k] - oy
        out[M1X, q], out[M1Y, q] = geo[G_M1X, k], geo[G_M1Y, k]
        out[M2X, q], out[M2Y, q] = geo[G_M2X, k], geo[G_M2Y, k]
    return first + count


@njit(cache=True, error_model="numpy")
def pad_bucket(out, lo, hi, x):
    """Inert sources (moment 0, at x + 1 m) in columns lo:hi of ``out``."""
    for q in range(lo, hi):
        out[SX, q], out[SY, q] = x + 1.0, 0.0
        out[M1X, q] = out[M1Y, q] = out[M2X, q] = out[M2Y, q] = 0.0


@njit(cache=True, fastmath=_FASTMATH, error_model="numpy")
def masked_copy(mx, my, mask, out_x, out_y):
    """out = m where mask, else 0, rounded to the type of ``out``."""
    for k in range(mask.shape[0]):
        out_x[k] = mx[k] * mask[k]
        out_y[k] = my[k] * mask[k]


@njit(cache=True, error_model="numpy")
def copy_columns(src, rows, index, count, dst, first):
    """dst[r, first + t] = src[r, index[t]] for the given rows and t < count."""
    for r in rows:
        s, d = src[r], dst[r, first:first + count]
        for t in range(count):
            d[t] = s[index[t]]


@njit(cache=True, fastmath=_FASTMATH, error_model="numpy")
def culled_everywhere(ls, owner, out):
    """out[k] = 1 where source k is culled in both columns at every agent (bound / threshold ``ls`` below 1 at the
    nearest agent with the largest weight), else 0; agents' bodies are never (each agent drops its own)."""
    for k in range(ls.shape[0]):
        out[k] = (ls[k] < 1.0) & (owner[k] == NOBODY)


@njit(cache=True, fastmath=_FASTMATH, error_model="numpy")
def share_far_sources(n, axy, s_max, c, level_lcq, level_e, lists, stage, want_error, dropped1, dropped2):
    """Split the first ``n`` sources of ``lists.lst`` into those every agent serves by the first far level, those
    every agent culls and the rest.

    ``axy``: DT[N, 2], the arena's agents; ``level_lcq``, ``level_e``: float64[L]
    (see :func:`dense_level_sources`); ``lists``, ``stage``: see
    :mod:`efish.physics.kernel_inputs`. The test runs once per arena at the
    distance of the nearest agent, with the Mormyromast moment T1 times the largest
    agent weight ``s_max``, so a shared source passes the per-agent test of every
    agent, and a source culled there (both columns below their thresholds) is
    culled at every agent: it is dropped here, once per arena, so that a looser
    tolerance saves the work of distant sources in large arenas too. Agents'
    bodies are never shared (each agent drops its own). Shared
    sources go to ``lists.shared`` (rows ``S_*``), the rest to ``lists.rest`` (rows
    ``L_*``, with ``lists.rest_own`` and ``lists.rest_owner``). Returns the rest as
    the :class:`~efish.physics.kernel_inputs.SourceList` each agent stages, with the
    bound sums of the shared and the dropped sources in both columns (for each agent's exact-zero test)
    and, when ``want_error``, the shared sources' interpolation error bounds plus the dropped ones' bounds (else 0).
    ``dropped1``, ``dropped2``: the bound sums (V/m, agent weight included) of pellets dropped earlier, whose
    images are not listed (:func:`efish.physics.sense_kernel.drop_culled_bodies`), added to both.
    """
    lst, geo, flag, order = lists.lst, stage.geo, stage.in_dense, stage.order
    own, owner = lists.own[:n], lists.owner[:n]
    d2 = geo[G_D2, :n]
    nearest_distance2(axy, lst[L_X, :n], lst[L_Y, :n], d2)
    inv1 = s_max / c[TOL_MORM]
    source_bounds(-2, d2, own, lst[L_A1, :n], lst[L_A2, :n], inv1, 1.0 / c[TOL_AMP], c[R_SENS], geo)
    unit, a1, a2, culled = geo[G_UNIT, :n], lst[L_A1, :n], lst[L_A2, :n], geo[G_KEEP, :n]
    culled_everywhere(geo[G_LS, :n], owner, culled)  # before G_LS turns into its log2
    dense_level_sources(n, geo, level_lcq, level_e, c, flag)
    n_shared = 0
    total1 = total2 = 0.0
    for k in range(n):  # branch-free compaction: shared first in ``order``
        take = flag[k] & (owner[k] == NOBODY) & (culled[k] == 0)
        order[n_shared] = k
        n_shared += take
        total1 += a1[k] * unit[k] * take
        total2 += a2[k] * unit[k] * take
    n_rest = 0
    rest_index = order[n_shared:n]
    for k in range(n):
        rest_index[n_rest] = k
        n_rest += ((flag[k] == 0) | (owner[k] != NOBODY)) & (culled[k] == 0)
    # what the culled sources may add at any agent: their bounds at the nearest one (column 1 per unit of
    # agent weight, like total1); the pellets dropped before their images were listed are added at the return
    skipped1 = skipped2 = 0.0
    for k in range(n):
        skipped1 += a1[k] * unit[k] * culled[k]
        skipped2 += a2[k] * unit[k] * culled[k]
    total1 += skipped1
    total2 += skipped2
    err1 = err2 = 0.0
    if want_error:  # their interpolation error at the nearest agent bounds it at every agent (farther, weight <= s_max)
        for k in range(n):
            culled[k] = flag[k] & (owner[k] == NOBODY) & (culled[k] == 0)  # now: the shared ones
        err1, err2 = level_error(culled, d2, unit, a1, a2, a1, a2, 2.0 ** level_lcq[0], int(level_e[0]), c[R_SENS])
        err1 += skipped1
        err2 += skipped2
    copy_columns(lst, (L_X, L_Y, L_T1X, L_T1Y, L_M2X, L_M2Y), order, n_shared, lists.shared, 0)
    copy_columns(lst, (L_X, L_Y, L_T1X, L_T1Y, L_M2X, L_M2Y, L_A1, L_A2), rest_index, n_rest, lists.rest, 0)
    rest_own, rest_owner = lists.rest_own, lists.rest_owner
    for t in range(n_rest):
        rest_own[t], rest_owner[t] = own[rest_index[t]], owner[rest_index[t]]
    error1 = err1 * s_max + dropped1 if want_error else 0.0  # dropped1 already carries the agent weight
    error2 = err2 + dropped2 if want_error else 0.0
    return SourceList(lists.rest, rest_own, rest_owner, n_rest, n_shared, True, total1 * s_max + dropped1,
                      total2 + dropped2, error1, error2)


@njit(cache=True, fastmath=_FASTMATH, error_model="numpy")
def copy_shared(ax, ay, weight, shared, n_shared, dense):
    """The shared sources as agent (ax, ay) evaluates them: float32, relative to it, Mormyromast moment x ``weight``."""
    x, y, t1x, t1y = shared[S_X, :n_shared], shared[S_Y, :n_shared], shared[S_T1X, :n_shared], shared[S_T1Y, :n_shared]
    ox, oy, o1x, o1y = dense[SX, :n_shared], dense[SY, :n_shared], dense[M1X, :n_shared], dense[M1Y, :n_shared]
    for q in range(n_shared):
        ox[q] = x[q] - ax
        oy[q] = y[q] - ay
        o1x[q] = weight * t1x[q]
        o1y[q] = weight * t1y[q]
    m2x, m2y, o2x, o2y = shared[S_M2X, :n_shared], shared[S_M2Y, :n_shared], dense[M2X, :n_shared], dense[M2Y, :n_shared]
    for q in range(n_shared):
        o2x[q] = m2x[q]
        o2y[q] = m2y[q]


@njit(cache=True, fastmath=_FASTMATH, error_model="numpy")
def weighted_moments(a, n, weight, lst, owner, geo):
    """Agent ``a``'s Mormyromast moments of listed sources in shared mode: weight x T1, 0 for its own body."""
    t1x, t1y, a1, own_body = lst[L_T1X, :n], lst[L_T1Y, :n], lst[L_A1, :n], owner[:n]
    p1x, p1y, p1a = geo[G_P1X, :n], geo[G_P1Y, :n], geo[G_A1, :n]
    for t in range(n):
        w = weight * (own_body[t] != a)
        p1x[t] = w * t1x[t]
        p1y[t] = w * t1y[t]
    for t in range(n):
        p1a[t] = abs(weight) * a1[t] * (own_body[t] != a)


@njit(cache=True, fastmath=_FASTMATH, error_model="numpy")
def imaged_moments(img, m1x, m1y, geo):
    """An agent's Mormyromast moments of every body image, from its per-body moments (full list only)."""
    image_rows(img, m1x, m1y, geo[G_P1X], geo[G_P1Y], geo[G_A1])


@njit(cache=True, error_model="numpy")
def bucket_offsets(bucket, offsets):
    """offsets (int64[L + 2]): bucket l of ``bucket`` (int64[n], -1: none) gets columns offsets[l]:offsets[l + 1].

    Each bucket is padded to a multiple of ``EXACT_BLOCK`` (bucket 0) or ``BLOCK``.
    """
    offsets[:] = 0
    for k in range(bucket.shape[0]):
        offsets[bucket[k] + 1] += bucket[k] >= 0
    for lv in range(offsets.shape[0] - 1):
        block = EXACT_BLOCK if lv == 0 else BLOCK
        offsets[lv + 1] = offsets[lv] + -(-offsets[lv + 1] // block) * block


@njit(cache=True, error_model="numpy")
def staged_error(n, geo, a2, in_dense, bucket, level_lcq, level_e, r):
    """Error bound of an agent's staged interpolated sources, both columns: the sum of :func:`level_error` over levels.

    Kept columns are the nonzero moments of ``geo`` rows G_M1X ... G_M2Y; ``bucket`` as in
    :func:`source_buckets` (level l in bucket l + 1; the first level is ``in_dense``).
    """
    d2, unit, a1 = geo[G_D2, :n], geo[G_UNIT, :n], geo[G_A1, :n]
    keep1, keep2 = geo[G_KEEP, :n], geo[G_LS, :n]  # G_LS is free once the buckets are chosen
    for k in range(n):
        keep1[k] = (geo[G_M1X, k] != 0) | (geo[G_M1Y, k] != 0)
        keep2[k] = (geo[G_M2X, k] != 0) | (geo[G_M2Y, k] != 0)
    if level_e.shape[0] == 0:
        return 0.0, 0.0
    err1, err2 = level_error(in_dense[:n], d2, unit, a1, a2, keep1, keep2, 2.0 ** level_lcq[0], int(level_e[0]), r)
    member = geo[G_LX, :n]  # G_LX is free too: the members of each higher level
    for lv in range(1, level_e.shape[0]):
        for k in range(n):
            member[k] = bucket[k] == lv + 1
        e1, e2 = level_error(member, d2, unit, a1, a2, keep1, keep2, 2.0 ** level_lcq[lv], int(level_e[lv]), r)
        err1 += e1
        err2 += e2
    return err1, err2


@njit(cache=True, fastmath=_FASTMATH, error_model="numpy")
def gather_sources(a, ax, ay, thr1, thr2, srcs, c, level_lcq, level_e, stage, want_error):
    """Stage the listed sources of ``srcs`` whose bound at agent ``a`` (at (ax, ay)) reaches a threshold, by level.

    ``stage.geo`` rows G_P1X, G_P1Y, G_A1 hold the agent's Mormyromast moments
    (:func:`weighted_moments` or :func:`imaged_moments`), ``stage.dense[:, :srcs.n_shared]``
    the shared sources. Column 1 (Mormyromast) and 2 (Ampullary) are culled against
    ``thr1``, ``thr2`` separately; a culled column is stored as 0. Sources of the first
    far level (``level_lcq``, ``level_e``: float64[L]) go to ``stage.dense`` after the
    shared ones (float32, relative to the agent), each in its own column with the
    others' moments zeroed: one long loop evaluates them. The rest, a few tens, are
    bucketed (:func:`bucket_offsets`): exact ones (bucket 0) to ``stage.exact`` in the
    working dtype, higher levels to the same columns of ``stage.far`` in float32
    (bucket 1, the dense level, stays empty); every bucket is padded with inert sources
    (moment 0, 1 m away), so its loops have no scalar remainder. Returns the number of
    dense columns (0 without far levels), the bound sums of both columns and the error
    bounds of both columns: the bounds of the culled sources plus :func:`staged_error`.
    """
    n, n_shared, lst, geo, in_dense, dense = srcs.n, srcs.n_shared, srcs.lst, stage.geo, stage.in_dense, stage.dense
    own, x, y, d2 = srcs.own[:n], lst[L_X, :n], lst[L_Y, :n], geo[G_D2, :n]
    distance2(ax, ay, x, y, d2)
    inv1 = 1.0 / thr1 if thr1 > 0 else 0.0
    inv2 = 1.0 / thr2 if thr2 > 0 else 0.0
    source_bounds(a, d2, own, geo[G_A1, :n], lst[L_A2, :n], inv1, inv2, c[R_SENS], geo)
    unit = geo[G_UNIT, :n]
    total1, skipped1 = cull_column(a, geo[G_A1, :n], geo[G_P1X, :n], geo[G_P1Y, :n], own, unit, thr1,
                                   geo[G_M1X, :n], geo[G_M1Y, :n])
    total2, skipped2 = cull_column(a, lst[L_A2, :n], lst[L_M2X, :n], lst[L_M2Y, :n], own, unit, thr2,
                                   geo[G_M2X, :n], geo[G_M2Y, :n])
    for k in range(n):
        geo[G_KEEP, k] = (geo[G_M1X, k] != 0) | (geo[G_M1Y, k] != 0) | (geo[G_M2X, k] != 0) | (geo[G_M2Y, k] != 0)
    n_levels = level_e.shape[0]
    if n_levels > 0:
        dense_level_sources(n, geo, level_lcq, level_e, c, in_dense)
    else:
        in_dense[:n] = False
    m = n_shared + n
    n_dense = -(-m // BLOCK) * BLOCK if n_levels > 0 else 0
    # rows sliced to start at the first listed source: a loop index from 0 keeps the copies vectorised
    ox, oy = dense[SX, n_shared:m], dense[SY, n_shared:m]
    for k in range(n):
        ox[k], oy[k] = x[k] - ax, y[k] - ay
    masked_copy(geo[G_M1X, :n], geo[G_M1Y, :n], in_dense[:n], dense[M1X, n_shared:m], dense[M1Y, n_shared:m])
    masked_copy(geo[G_M2X, :n], geo[G_M2Y, :n], in_dense[:n], dense[M2X, n_shared:m], dense[M2Y, n_shared:m])
    pad_bucket(dense, m, n_dense, 0.0)
    # the others, a few tens, by bucket
    bucket, members, offsets, exact, far = stage.order[:n], stage.order[n:2 * n], stage.offsets, stage.exact, stage.far
    if n_levels > 0:
        source_buckets(n, geo, in_dense, level_lcq, level_e, c, bucket)
    else:
        for k in range(n):
            bucket[k] = 0 if geo[G_KEEP, k] != 0 else -1
    bucket_offsets(bucket, offsets)
    end = fill_bucket(bucket, 0, x, y, geo, 0.0, 0.0, members, exact, 0)  # exact: absolute positions
    pad_bucket(exact, end, offsets[1], ax)
    for lv in range(2, offsets.shape[0] - 1):  # bucket 1, the dense level, stays empty
        if offsets[lv + 1] > offsets[lv]:
            end = fill_bucket(bucket, lv, x, y, geo, ax, ay, members, far, offsets[lv])
            pad_bucket(far, end, offsets[lv + 1], 0.0)
    if not want_error:  # the bound costs a pass over every staged source: only when asked
        return n_dense, total1, total2, 0.0, 0.0
    err1, err2 = staged_error(n, geo, lst[L_A2, :n], in_dense, bucket, level_lcq, level_e, c[R_SENS])
    return n_dense, total1, total2, skipped1 + err1, skipped2 + err2
