"""The induction step, p = alpha E (docs/model/physics.md#induction): its one home,
:func:`efish.physics.fields.induced_dipole`, against the field worked out by hand, and the numba kernels that
write the same step into their loops against that home."""

from __future__ import annotations

import numpy as np
import pytest

from efish.config import EfishConfig
from efish.physics import Scene, build_plan, image_sources, monopole_field
from efish.physics.fast import kernel_constants
from efish.physics.fields import coulomb_constant, induced_dipole, pairwise_dipole_field, pairwise_monopole_field
from efish.physics.kernels import image_table, induced_dipoles
from efish.physics.reference import eod_monopoles
from efish.rollout.measure_kernels import field_sums

PLAN = build_plan(EfishConfig(), Scene(agents=3, emitters=True, pellets=True), tolerance=0.0, dtype="float64")
K = coulomb_constant(PLAN.eps0)
Q, H = PLAN.eod_charge, PLAN.eod_half_separation  # +q at H ahead of the body centre, -q at H behind
ALPHA = PLAN.alpha_agent


def two_fish(other_xy: list[float]) -> np.ndarray:
    """Dipoles (2, 2) C*m induced in two agents, fish 0 at the origin emitting along +x, fish 1 silent at
    ``other_xy`` m: fish 0's EOD monopoles in free space, no softening."""
    bodies = np.array([[0.0, 0.0], other_xy])
    positions, charges = eod_monopoles(bodies[0], 0.0, PLAN)
    return induced_dipole(np.full(2, ALPHA), monopole_field(bodies, positions, charges, softening=0.0), own=0)


@pytest.mark.parametrize("x", [0.03, 0.1, 0.4])
def test_ahead_of_an_emitter_the_induced_dipole_is_alpha_times_the_monopole_pairs_axial_field(x):
    p = two_fish([x, 0.0])
    # on the axis: k q / (x - H)^2 from +q, minus k q / (x + H)^2 from -q, along +x
    e_by_hand = K * Q * (1.0 / (x - H) ** 2 - 1.0 / (x + H) ** 2)
    assert p[1, 0] == pytest.approx(ALPHA * e_by_hand, rel=1e-13)
    assert p[1, 1] == 0.0
    assert p[1, 0] < 0 < e_by_hand  # an insulator (chi < 0): the dipole turns against the field
    assert np.all(p[0] == 0.0)      # the emitter is not polarised by its own EOD


@pytest.mark.parametrize("y", [0.03, 0.1, 0.4])
def test_beside_an_emitter_the_induced_dipole_is_alpha_times_the_broadside_field(y):
    p = two_fish([0.0, y])
    # broadside: the two charges' y parts cancel, their x parts add to -2 k q H / (H^2 + y^2)^(3/2)
    e_by_hand = -2.0 * K * Q * H / (H * H + y * y) ** 1.5
    assert p[1, 0] == pytest.approx(ALPHA * e_by_hand, rel=1e-13)
    assert p[1, 1] == pytest.approx(0.0, abs=1e-15 * abs(p[1, 0]))


def test_far_from_the_emitter_its_eod_is_a_point_dipole_and_induces_alpha_times_that_field():
    """At distances r >> H the monopole pair is a dipole of moment 2 q H: on axis 2 k (2 q H) / r^3, broadside
    -k (2 q H) / r^3 (relative error of order (H / r)^2)."""
    r, p_eod = 100 * H, 2 * Q * H
    assert two_fish([r, 0.0])[1, 0] == pytest.approx(ALPHA * 2 * K * p_eod / r**3, rel=1e-3)
    assert two_fish([0.0, r])[1, 0] == pytest.approx(-ALPHA * K * p_eod / r**3, rel=1e-3)


def test_alpha_broadcasts_over_leading_axes_and_own_is_plus_zero():
    e = np.arange(24.0).reshape(2, 3, 2, 2) + 1.0           # [B, N, bodies, 2]
    alpha = np.array([-2.0, -3.0])                          # per body
    p = induced_dipole(alpha, e, own=1)
    np.testing.assert_array_equal(p[..., 0, :], -2.0 * e[..., 0, :])
    assert np.all(p[..., 1, :] == 0.0) and not np.any(np.signbit(p[..., 1, :]))
    np.testing.assert_array_equal(induced_dipole(-2.0, e), -2.0 * e)  # a scalar alpha: every body alike


def test_the_induction_kernel_agrees_with_the_one_home():
    """efish.physics.kernels.induced_dipoles (the fast path's loop) equals induced_dipole of each emitter's
    EOD field with its wall images (the reference's way), silent agents' parts zero."""
    rng = np.random.default_rng(11)
    w, h = 0.7, 0.5
    agents, pellets = rng.uniform(0.05, 0.45, (3, 2)), rng.uniform(0.05, 0.45, (5, 2))
    heading, emitting = rng.uniform(-np.pi, np.pi, 3), np.array([True, False, True])
    bodies = np.concatenate([agents, pellets])
    alpha = np.concatenate([np.full(3, PLAN.alpha_agent), np.full(5, PLAN.alpha_pellet)])
    c, _ = kernel_constants(PLAN)
    img = image_table(w, h, PLAN.image_indices, PLAN.image_weights, c)
    p_ind = np.full((3, 2, len(bodies) + 4), np.nan)  # room for more bodies than there are, as the fast path's
    induced_dipoles(agents, heading, emitting, bodies[:, 0].copy(), bodies[:, 1].copy(), alpha, img, c, p_ind)
    for e in range(3):
        kernel = p_ind[e, :, :len(bodies)].T
        if not emitting[e]:
            assert np.all(kernel == 0.0)
            continue
        pos, q = eod_monopoles(agents[e], heading[e], PLAN)
        ipos, _, wq = image_sources(pos, None, w, h, PLAN.image_indices, PLAN.image_scale)
        e_at = monopole_field(bodies, ipos, np.tile(q, len(PLAN.image_indices)) * wq,
                              softening=np.sqrt(PLAN.softening2), eps0=PLAN.eps0)
        home = induced_dipole(alpha, e_at, own=e)
        assert np.all(kernel[e] == 0.0) and np.all(home[e] == 0.0)
        np.testing.assert_allclose(kernel, home, rtol=1e-12, atol=1e-12 * np.abs(home).max())


def test_the_recorded_fields_kernel_induces_what_the_one_home_does():
    """efish.rollout.measure_kernels.field_sums' Mormyromast sum (over k) is the field at the agent's centre of
    induced_dipole(alpha, the agent's free-space EOD field at each body)."""
    rng = np.random.default_rng(5)
    xy = rng.uniform(0.0, 0.3, (6, 2))
    alpha = np.concatenate([np.full(2, PLAN.alpha_agent), np.full(4, PLAN.alpha_pellet)])
    src = np.zeros((5, 6))
    src[0], src[1], src[4] = xy[:, 0], xy[:, 1], alpha          # no intrinsic moments: rows 2, 3 stay 0
    centre, heading, soft = np.array([0.15, 0.12]), 0.7, np.sqrt(PLAN.softening2)
    u = H * np.array([np.cos(heading), np.sin(heading)])
    *_, mx, my = field_sums(src, 0, 6, centre[0], centre[1], u[0], u[1], K * Q, PLAN.softening2)
    positions, charges = eod_monopoles(centre, heading, PLAN)
    e_eod = pairwise_monopole_field(xy[:, None], positions, charges, softening=soft, eps0=PLAN.eps0).sum(1)
    home = pairwise_dipole_field(centre, xy, induced_dipole(alpha, e_eod), softening=soft, eps0=PLAN.eps0).sum(0)
    np.testing.assert_allclose(K * np.array([mx, my]), home, rtol=1e-12)
