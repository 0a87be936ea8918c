"""Pellets every agent culls leave the source list once per arena, with their bounds carried.

:func:`efish.physics.sense_kernel.drop_culled_bodies` drops a pellet when its
bound at the nearest agent, in both columns, is below the thresholds (the
Mormyromast one from a bound on the moment the emitters could induce in it);
the bounds it returns must be the sums of those bounds times the image
weights' magnitudes, and everything it keeps must be the kept pellets, in order.
"""

from __future__ import annotations

import numpy as np
import pytest

from efish.physics import kernels as kn
from efish.physics.fast import kernel_constants
from efish.physics.kernel_inputs import Arena
from efish.physics.plan import build_plan
from efish.physics.sense_kernel import B_ALPHA, B_M2X, B_M2Y, B_X, B_Y, N_BODY, drop_culled_bodies
from efish.physics.sources import BLOCK

from ..helpers import cfg_with


@pytest.mark.parametrize("tolerance, ampullary", [(1e-2, True), (1e-7, False)],
                         ids=["ampullary-decides", "induction-decides"])
def test_dropped_pellets_are_those_below_both_thresholds_and_their_bounds_are_carried(tolerance, ampullary):
    rng = np.random.default_rng(0)
    c = kernel_constants(build_plan(cfg_with(f"physics.tolerance={tolerance}")))[0]
    n, n_pel, side = 2, 300, 3.0  # m
    nb = -(-(n + n_pel) // BLOCK) * BLOCK
    body = np.zeros((N_BODY, nb))
    body[B_X, :n + n_pel], body[B_Y, :n + n_pel] = rng.uniform(0, side, (2, n + n_pel))
    body[[B_X, B_Y], n:n + 20] = body[[B_X, B_Y], :1] + rng.uniform(-0.08, 0.08, (2, 20))  # some beside agent 0
    body[B_X, n + n_pel:] = body[B_Y, n + n_pel:] = 100.0  # inert padding, as fill_bodies leaves it
    phi = rng.uniform(0, 2 * np.pi, n + n_pel)
    m2 = c[kn.K] * c[kn.P_PELLET] if ampullary else 0.0
    body[B_M2X, :n + n_pel], body[B_M2Y, :n + n_pel] = -m2 * np.sin(phi), m2 * np.cos(phi)
    body[B_ALPHA, :n], body[B_ALPHA, n:n + n_pel] = c[kn.ALPHA_AGENT], c[kn.ALPHA_PELLET]
    axy = body[[B_X, B_Y], :n].T.copy()
    emitting = np.array([True, False])
    arena = Arena(axy, np.zeros(n), emitting, np.zeros((1, 5)))
    before = body.copy()
    s_max, image_sum = 120.0, 4.8

    kept_nb, got1, got2 = drop_culled_bodies(body, n, nb, arena, s_max, c, image_sum, m2, side * np.sqrt(2))

    pellets = before[:, n:n + n_pel]
    d = np.sqrt(((pellets[[B_X, B_Y]].T[:, None, :] - axy[None]) ** 2).sum(-1))  # [pellet, agent]
    unit = 2.0 / (d.min(axis=1) - c[kn.R_SENS]) ** 3
    h, kq = c[kn.HALF_SEP], c[kn.K] * c[kn.Q]
    t1 = np.abs(pellets[B_ALPHA]) * image_sum * 4 * kq * h / (d[:, 0] - h) ** 3  # agent 0 emits, agent 1 is silent
    b1 = s_max * t1 * unit
    b2 = np.hypot(pellets[B_M2X], pellets[B_M2Y]) * unit
    drop = (b1 < c[kn.TOL_MORM]) & (b2 < c[kn.TOL_AMP])
    assert 0 < drop.sum() < n_pel  # the scene has both kinds
    kept = n + int((~drop).sum())
    assert kept_nb == -(-kept // BLOCK) * BLOCK
    np.testing.assert_array_equal(body[:, :n], before[:, :n])  # agents stay first, untouched
    for row in (B_X, B_Y, B_ALPHA, B_M2X, B_M2Y):
        np.testing.assert_array_equal(body[row, n:kept], pellets[row, ~drop])
    assert np.all(body[B_X, kept:kept_nb] == 100.0) and np.all(body[B_ALPHA:, kept:kept_nb] == 0)
    np.testing.assert_allclose([got1, got2], [image_sum * b1[drop].sum(), image_sum * b2[drop].sum()], rtol=1e-12)


def test_no_pellet_is_dropped_when_the_arena_is_within_every_pellets_reach():
    c = kernel_constants(build_plan(cfg_with()))[0]  # tolerance 1e-7: a pellet's Ampullary field reaches ~10 m
    body = np.zeros((N_BODY, BLOCK))
    body[B_X, :4], body[B_Y, :4] = [0.1, 0.2, 0.5, 0.6], [0.1, 0.2, 0.5, 0.6]
    m2 = c[kn.K] * c[kn.P_PELLET]
    arena = Arena(body[[B_X, B_Y], :2].T.copy(), np.zeros(2), np.array([True, True]), np.zeros((1, 5)))
    nb, got1, got2 = drop_culled_bodies(body, 2, BLOCK, arena, 1.0, c, 5.0, m2, 0.99)
    assert (nb, got1, got2) == (BLOCK, 0.0, 0.0)
