"""Numba primitives of the fast path: point fields at sensors, images, induction.

Same formulas as :mod:`efish.physics.reference`. Kernels are pure functions
of plain arrays. They are type-generic: every constant arrives in the ``consts``
array of the working dtype, so float32 inputs stay float32 throughout (a bare
float literal would promote to float64).

Two observations keep the inner loops short:
- fields are linear in the moments, so the gated Mormyromast reading
  g_self * self + g_cons * c * cons is the field of one combined moment per
  body: one dipole evaluation per (source, sensor) instead of two;
- sensors sit on a circle, so cos/sin of sensor angles come from one cos/sin
  of the heading and precomputed angle tables.
The per-agent assembly lives in :mod:`efish.physics.sense_kernel`.
"""

from __future__ import annotations

import numpy as np

from .._jit import njit

# Indices into the ``consts`` array (module-level ints are compile-time constants).
K, Q, HALF_SEP, P_AGENT, P_PELLET, ALPHA_AGENT, ALPHA_PELLET, SOFT2, R_SENS = range(9)
TOL_MORM, TOL_AMP, ZERO_MORM, ZERO_AMP, KNOLL_ZERO, G_SELF, G_CONS, K_CONS = range(9, 17)
ONE, TWO, THREE, ZERO, FAR_MAX_LX, FAR_MAX_LS, N_CONSTS = 17, 18, 19, 20, 21, 22, 23
# Indices into the ``flags`` array.
DO_MORM, DO_AMP, DO_KNOLL, DO_INDUCTION, DO_WALLDIST, DO_PELLETS, CULL, ERROR_BOUND, N_FLAGS = range(9)
# Columns of the source list built per agent: position, Mormyromast moment, Ampullary moment.
SX, SY, M1X, M1Y, M2X, M2Y, N_SRC = range(7)

_FASTMATH = {"contract", "arcp", "reassoc"}  # no nnan/ninf: hard cases must keep their NaN checks
# error_model="numpy" on every kernel: Python's model puts a zero check before
# each division, which blocks vectorisation; divisors here are softened or floored.


@njit(cache=True, fastmath=_FASTMATH, error_model="numpy")
def add_monopole(out, sx, sy, nx, ny, px, py, kq, soft2, one):
    """out[s] += (field of charge q at (px, py)) . n[s]; kq = k * q."""
    for s in range(out.shape[0]):
        dx = sx[s] - px
        dy = sy[s] - py
        inv_r2 = one / (dx * dx + dy * dy + soft2)
        out[s] += kq * (dx * nx[s] + dy * ny[s]) * inv_r2 * np.sqrt(inv_r2)


@njit(cache=True, error_model="numpy")
def place_on_circle(x, y, ch, sh, cos_a, sin_a, radius, sx, sy, nx, ny):
    """Points and outward normals on a circle around (x, y) at angles a + heading, from cos/sin of both."""
    for s in range(cos_a.shape[0]):
        nx[s] = ch * cos_a[s] - sh * sin_a[s]
        ny[s] = sh * cos_a[s] + ch * sin_a[s]
        sx[s] = x + radius * nx[s]
        sy[s] = y + radius * ny[s]


@njit(cache=True, error_model="numpy")
def place_sensors(x, y, heading, cos_a, sin_a, radius, sx, sy, nx, ny):
    """Sensor positions and outward normals on a circle around (x, y)."""
    place_on_circle(x, y, np.cos(heading), np.sin(heading), cos_a, sin_a, radius, sx, sy, nx, ny)


@njit(cache=True, error_model="numpy")
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


@njit(cache=True, fastmath=_FASTMATH, error_model="numpy")
def induced_dipoles(axy, heading, emitting, bx, by, alpha, img, c, p_ind):
    """p_ind[e, 0/1, body] = alpha_body * E_e(body) for every emitter e, own EOD excluded
    (docs/model/physics.md#induction). The step is :func:`efish.physics.fields.induced_dipole`'s, written
    out here because a kernel cannot call that numpy function: the field is summed straight into ``p_ind``, in
    the working dtype, and multiplied by alpha in place. tests/physics/test_induction.py holds the two equal.

    E_e is the field of e's two monopoles and all their wall images. Bodies are
    the innermost, contiguous loop so the sums vectorise; silent agents' rows are zero.
    ``p_ind`` may have room for more bodies than ``bx``: its rows are sliced here, so
    numba sees them contiguous (a slice of the last axis taken by the caller is not).
    """
    kq, soft2, one = c[K] * c[Q], c[SOFT2], c[ONE]
    nb = bx.shape[0]
    for e in range(axy.shape[0]):
        px, py = p_ind[e, 0, :nb], p_ind[e, 1, :nb]
        px[:] = c[ZERO]
        py[:] = c[ZERO]
        if not emitting[e]:
            continue
        ux = c[HALF_SEP] * np.cos(heading[e])
        uy = c[HALF_SEP] * np.sin(heading[e])
        for i in range(img.shape[0]):
            for sign in (one, -one):
                mx = img[i, 0] + img[i, 1] * (axy[e, 0] + sign * ux)
                my = img[i, 2] + img[i, 3] * (axy[e, 1] + sign * uy)
                kqw = sign * kq * img[i, 4]
                for j in range(bx.shape[0]):
                    dx = bx[j] - mx
                    dy = by[j] - my
                    inv_r2 = one / (dx * dx + dy * dy + soft2)
                    f = kqw * inv_r2 * np.sqrt(inv_r2)
                    px[j] += f * dx
                    py[j] += f * dy
        for j in range(bx.shape[0]):  # p = alpha E, as efish.physics.fields.induced_dipole
            px[j] *= alpha[j]
            py[j] *= alpha[j]
        px[e] = c[ZERO]  # a body is not polarised by its own EOD
        py[e] = c[ZERO]


@njit(cache=True, fastmath=_FASTMATH, error_model="numpy")
def far_readings(src, lo, hi, qx, qy, qnx, qny, c, out1, out2):
    """E.n at the far-field points of both moment columns of sources ``lo:hi`` of ``src``.

    Loops over sources innermost, so the sums vectorise; the two moments share
    one geometry (distance, powers) per source and point. The rows are sliced
    first so the loop index starts at 0: numba must otherwise allow for a
    negative index at every access, which blocks vectorisation.
    """
    one, three, soft2 = c[ONE], c[THREE], c[SOFT2]
    x, y = src[SX, lo:hi], src[SY, lo:hi]
    m1x, m1y, m2x, m2y = src[M1X, lo:hi], src[M1Y, lo:hi], src[M2X, lo:hi], src[M2Y, lo:hi]
    for q in range(qx.shape[0]):
        acc1 = acc2 = c[ZERO]
        for i in range(x.shape[0]):
            dx = qx[q] - x[i]
            dy = qy[q] - y[i]
            inv_r2 = one / (dx * dx + dy * dy + soft2)
            inv_r3 = inv_r2 * np.sqrt(inv_r2)
            d_dot_n = (dx * qnx[q] + dy * qny[q]) * three * inv_r2
            acc1 += inv_r3 * ((m1x[i] * dx + m1y[i] * dy) * d_dot_n - (m1x[i] * qnx[q] + m1y[i] * qny[q]))
            acc2 += inv_r3 * ((m2x[i] * dx + m2y[i] * dy) * d_dot_n - (m2x[i] * qnx[q] + m2y[i] * qny[q]))
        out1[q] = acc1
        out2[q] = acc2
