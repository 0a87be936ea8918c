"""Closed-form point-source fields (docs/model/physics.md#field-sources) and the calibration ratios of
docs/model/sensors.md#calibration-checks."""

from __future__ import annotations

import numpy as np
import pytest

from efish.config.schema import PhysicsConfig
from efish.physics import coulomb_constant, dipole_field, monopole_field

EPS0, SOFTENING_M = PhysicsConfig().eps0, PhysicsConfig().softening_m  # the fields' keyword defaults

K = 1.0 / (4.0 * np.pi * EPS0)
CM = 0.01
Q = 1.11e-15          # EOD monopole charge, C (docs/model/physics.md#field-sources)
P_EOD = Q * 1.0 * CM  # +q and -q 1 cm apart: EOD dipole moment, C m


def test_coulomb_constant():
    # eps0 of docs/model/physics.md#field-sources = 8.854e-12 F/m (not CODATA's 8.8541878e-12): k = 8.98774e9 V m / C
    assert coulomb_constant() == pytest.approx(8.98774e9, rel=1e-5)
    assert EPS0 == 8.854e-12
    assert coulomb_constant(2 * EPS0) == pytest.approx(coulomb_constant() / 2, rel=1e-15)


@pytest.mark.parametrize("x", [1e-3, 0.01, 0.05, 0.3])
@pytest.mark.parametrize("q", [1e-15, -3e-12])
def test_monopole_on_axis_is_kq_over_x2(x, q):
    e = monopole_field([[x, 0.0]], [[0.0, 0.0]], [q], softening=0.0)
    assert e.shape == (1, 2) and e.dtype == np.float64
    assert e[0, 0] == pytest.approx(K * q / x**2, rel=1e-12)
    assert e[0, 1] == 0.0


def test_monopole_points_away_from_positive_charge_in_every_direction():
    ang = np.linspace(0, 2 * np.pi, 17)
    src = np.array([[0.2, -0.1]])
    pts = src + 0.04 * np.column_stack([np.cos(ang), np.sin(ang)])
    e = monopole_field(pts, src, [2e-15], softening=0.0)
    expected = K * 2e-15 / 0.04**2 * np.column_stack([np.cos(ang), np.sin(ang)])
    np.testing.assert_allclose(e, expected, rtol=1e-10, atol=1e-12 * np.abs(expected).max())


@pytest.mark.parametrize("x", [1e-3, 0.01, 0.1])
def test_dipole_on_axis_is_p_over_2pi_eps0_x3(x):
    p = 1.11e-17
    e = dipole_field([[x, 0.0], [-x, 0.0]], [[0.0, 0.0]], [[p, 0.0]], softening=0.0)
    expected = p / (2 * np.pi * EPS0 * x**3)
    # both sides of the dipole: the on-axis field points along p
    np.testing.assert_allclose(e[:, 0], [expected, expected], rtol=1e-12)
    np.testing.assert_array_equal(e[:, 1], 0.0)


@pytest.mark.parametrize("x", [1e-3, 0.01, 0.1])
def test_dipole_on_axis_with_default_softening_far_from_the_source(x):
    # x >= 100 eps: the softening changes the field by ~ 4 (eps / x)^2 <= 4e-4
    p = 1.11e-17
    e = dipole_field([[x, 0.0]], [[0.0, 0.0]], [[p, 0.0]])
    assert e[0, 0] == pytest.approx(p / (2 * np.pi * EPS0 * x**3), rel=5 * (SOFTENING_M / x) ** 2)


def test_dipole_broadside_field_is_minus_kp_over_y3():
    p, y = 2e-20, 0.03
    e = dipole_field([[0.0, y]], [[0.0, 0.0]], [[p, 0.0]], softening=0.0)
    np.testing.assert_allclose(e[0], [-K * p / y**3, 0.0], rtol=1e-12, atol=1e-30)


def test_softening_matches_the_softened_formula_and_keeps_a_source_on_the_point_finite():
    eps, p, q = 1e-5, 1e-20, 1e-15
    x = eps  # a point as close as the softening length
    r2 = x * x + eps * eps
    e_d = dipole_field([[x, 0.0]], [[0.0, 0.0]], [[p, 0.0]], softening=eps)
    assert e_d[0, 0] == pytest.approx(K * (3 * p * x * x / r2**2.5 - p / r2**1.5), rel=1e-12)
    e_m = monopole_field([[x, 0.0]], [[0.0, 0.0]], [q], softening=eps)
    assert e_m[0, 0] == pytest.approx(K * q * x / r2**1.5, rel=1e-12)
    # source exactly on the observation point: finite; monopole 0, dipole -k p / eps^3
    on_m = monopole_field([[0.1, 0.1]], [[0.1, 0.1]], [q])
    on_d = dipole_field([[0.1, 0.1]], [[0.1, 0.1]], [[p, 0.0]])
    np.testing.assert_array_equal(on_m, 0.0)
    np.testing.assert_allclose(on_d[0], [-K * p / SOFTENING_M**3, 0.0], rtol=1e-12)


def test_fields_superpose_and_scale_linearly():
    rng = np.random.default_rng(0)
    pts = rng.uniform(-0.1, 0.1, (7, 2))
    pos = rng.uniform(0.2, 0.3, (4, 2))
    q = rng.normal(size=4) * 1e-15
    m = rng.normal(size=(4, 2)) * 1e-20
    total = monopole_field(pts, pos, q)
    parts = sum(monopole_field(pts, pos[i:i + 1], q[i:i + 1]) for i in range(4))
    np.testing.assert_allclose(total, parts, rtol=1e-12)
    np.testing.assert_allclose(monopole_field(pts, pos, -2 * q), -2 * total, rtol=1e-14)
    total = dipole_field(pts, pos, m)
    parts = sum(dipole_field(pts, pos[i:i + 1], m[i:i + 1]) for i in range(4))
    np.testing.assert_allclose(total, parts, rtol=1e-12)
    np.testing.assert_allclose(dipole_field(pts, pos, 3 * m), 3 * total, rtol=1e-14)


def test_dipole_is_the_far_field_of_a_monopole_pair():
    # +q at +h, -q at -h along a random axis; far away (D = 50 h) the pair is a dipole 2 q h
    rng = np.random.default_rng(1)
    h, q = 0.005, 1.11e-15
    u = np.array([np.cos(0.7), np.sin(0.7)])
    ang = rng.uniform(0, 2 * np.pi, 9)
    pts = 0.25 * np.column_stack([np.cos(ang), np.sin(ang)])
    pair = monopole_field(pts, np.stack([h * u, -h * u]), [q, -q], softening=0.0)
    dip = dipole_field(pts, [[0.0, 0.0]], [2 * q * h * u], softening=0.0)
    # the octupole correction is O((h / D)^2) = 4e-4 relative to |E|
    np.testing.assert_allclose(pair, dip, atol=2e-3 * np.abs(dip).max())


def test_no_sources_gives_zero_field():
    e = dipole_field([[0.0, 0.0], [1.0, 1.0]], np.zeros((0, 2)), np.zeros((0, 2)))
    assert e.shape == (2, 2)
    np.testing.assert_array_equal(e, 0.0)


# ------------------------------------ calibration ratios (docs/model/sensors.md#calibration-checks)
def test_self_eod_vs_prey_induced_ratio():
    """Self-EOD field at a sensor / prey-induced field there = x^3 |x-r|^3 / (2 |chi| R^3 r^3).

    Everything on the body axis, the EOD treated as a point dipole (the
    approximation the supplement formula makes), prey at x = 5 cm, R = 0.25 cm,
    sensor at r = 1 cm, chi = -0.5: the ratio is 5.12e5, "about 1e6".
    """
    x, r, R, chi = 5 * CM, 1 * CM, 0.25 * CM, -0.5
    sensor, prey = np.array([[r, 0.0]]), np.array([[x, 0.0]])
    eod = dict(positions=[[0.0, 0.0]], moments=[[P_EOD, 0.0]])
    e_self = dipole_field(sensor, **eod)
    e_at_prey = dipole_field(prey, **eod)
    p_ind = 4 * np.pi * EPS0 * R**3 * chi * e_at_prey           # docs/model/physics.md#induction
    e_ind = dipole_field(sensor, prey, p_ind)
    ratio = np.linalg.norm(e_self) / np.linalg.norm(e_ind)
    formula = x**3 * abs(x - r) ** 3 / (2 * abs(chi) * R**3 * r**3)
    assert formula == pytest.approx(5.12e5, rel=1e-9)
    # same dipole approximation on both sides: exact up to the softening (~1e-6)
    assert ratio == pytest.approx(formula, rel=1e-4)
    # chi < 0: the induced field at the sensor opposes the own EOD field there
    assert e_ind[0, 0] * e_self[0, 0] < 0


def test_self_vs_prey_ratio_with_the_real_monopole_pair_at_the_prey():
    # Only the far field at the prey is replaced by the monopole pair: within a few percent.
    x, r, R, chi, h = 5 * CM, 1 * CM, 0.25 * CM, -0.5, 0.5 * CM
    prey = np.array([[x, 0.0]])
    e_at_prey = monopole_field(prey, [[h, 0.0], [-h, 0.0]], [Q, -Q])
    e_dip = dipole_field(prey, [[0.0, 0.0]], [[P_EOD, 0.0]])
    assert e_at_prey[0, 0] == pytest.approx(e_dip[0, 0], rel=0.03)
    p_ind = 4 * np.pi * EPS0 * R**3 * chi * e_at_prey
    e_ind = dipole_field([[r, 0.0]], prey, p_ind)
    e_self = dipole_field([[r, 0.0]], [[0.0, 0.0]], [[P_EOD, 0.0]])
    formula = x**3 * (x - r) ** 3 / (2 * abs(chi) * R**3 * r**3)
    assert abs(e_self[0, 0] / e_ind[0, 0]) == pytest.approx(formula, rel=0.04)


def test_self_vs_conspecific_eod_ratio_is_729_at_10_cm():
    """Own EOD at a sensor (r = 1 cm) vs a conspecific's at x = 10 cm: (x - r)^3 / r^3 = 729."""
    x, r = 10 * CM, 1 * CM
    sensor = np.array([[r, 0.0]])
    e_self = dipole_field(sensor, [[0.0, 0.0]], [[P_EOD, 0.0]])
    e_cons = dipole_field(sensor, [[x, 0.0]], [[P_EOD, 0.0]])
    assert (x - r) ** 3 / r**3 == pytest.approx(729.0)
    # default softening shifts the own field at r = 1 cm by ~ 3 (eps / r)^2 = 3e-6
    assert e_self[0, 0] / e_cons[0, 0] == pytest.approx(729.0, rel=1e-5)
    # the conspecific's real monopole pair at 9 cm is its dipole to < 1 %
    e_pair = monopole_field(sensor, [[x + 0.5 * CM, 0.0], [x - 0.5 * CM, 0.0]], [Q, -Q])
    assert e_pair[0, 0] == pytest.approx(e_cons[0, 0], rel=0.01)


# ------------------------------------------------------------------ bad input
@pytest.mark.parametrize("kwargs, name", [
    (dict(points=[0.0, 1.0], positions=[[0.0, 0.0]], charges=[1.0]), "points"),
    (dict(points=[[0.0, 1.0]], positions=[[0.0, 0.0, 0.0]], charges=[1.0]), "positions"),
    (dict(points=[[0.0, 1.0]], positions=[[0.0, 0.0]], charges=[1.0, 2.0]), "charges"),
    (dict(points=[[np.nan, 1.0]], positions=[[0.0, 0.0]], charges=[1.0]), "points"),
    (dict(points=[[0.0, 1.0]], positions=[[np.inf, 0.0]], charges=[1.0]), "positions"),
])
def test_monopole_field_rejects_bad_input(kwargs, name):
    with pytest.raises(ValueError, match=name):
        monopole_field(**kwargs)


@pytest.mark.parametrize("kwargs, name", [
    (dict(points=[[0.0, 1.0]], positions=[[0.0, 0.0]], moments=[1.0, 0.0]), "moments"),
    (dict(points=[[0.0, 1.0]], positions=[[0.0, 0.0]], moments=[[1.0, 0.0], [0.0, 1.0]]), "moments"),
    (dict(points=[[0.0, 1.0]], positions=[[0.0, 0.0]], moments=[[np.nan, 0.0]]), "moments"),
    (dict(points=np.zeros((2, 3)), positions=[[0.0, 0.0]], moments=[[1.0, 0.0]]), "points"),
])
def test_dipole_field_rejects_bad_input(kwargs, name):
    with pytest.raises(ValueError, match=name):
        dipole_field(**kwargs)


# ------------------------------------------------------------- pairwise fields and polarisability
def test_the_pairwise_fields_summed_over_sources_are_the_summed_fields():
    """pairwise_* give each source's field at its own point; summed over the sources they are monopole_field and
    dipole_field, whose per-source terms they share."""
    from efish.physics.fields import pairwise_dipole_field, pairwise_monopole_field

    rng = np.random.default_rng(3)
    points, positions = rng.uniform(0, 0.7, (9, 2)), rng.uniform(0, 0.7, (5, 2))
    charges, moments = rng.normal(0, 1e-15, 5), rng.normal(0, 1e-23, (5, 2))
    pairs_q = pairwise_monopole_field(points[:, None], positions[None], charges)         # (9, 5, 2)
    pairs_p = pairwise_dipole_field(points[:, None], positions[None], moments[None])     # (9, 5, 2)
    assert pairs_q.shape == pairs_p.shape == (9, 5, 2)
    np.testing.assert_allclose(pairs_q.sum(1), monopole_field(points, positions, charges), rtol=1e-13)
    np.testing.assert_allclose(pairs_p.sum(1), dipole_field(points, positions, moments), rtol=1e-13)
    for k in range(5):  # one source: the same numbers, pair by pair
        np.testing.assert_allclose(pairs_q[:, k], monopole_field(points, positions[k:k + 1], charges[k:k + 1]),
                                   rtol=1e-15)
        np.testing.assert_allclose(pairs_p[:, k], dipole_field(points, positions[k:k + 1], moments[k:k + 1]),
                                   rtol=1e-15)


def test_the_pairwise_fields_broadcast_over_leading_axes():
    from efish.physics.fields import pairwise_dipole_field, pairwise_monopole_field

    points = np.zeros((3, 4, 2)) + [0.1, 0.0]        # one point, repeated over a [3, 4] batch
    e = pairwise_monopole_field(points, [0.0, 0.0], Q, softening=0.0)
    assert e.shape == (3, 4, 2) and np.all(e[..., 0] == e[0, 0, 0]) and e[0, 0, 0] == pytest.approx(K * Q / 0.1**2)
    e = pairwise_dipole_field(points, np.zeros((3, 1, 2)), [P_EOD, 0.0], softening=0.0)
    assert e.shape == (3, 4, 2) and e[0, 0, 0] == pytest.approx(2 * K * P_EOD / 0.1**3, rel=1e-12)


def test_polarisability_is_4_pi_eps0_r3_chi_and_the_plans():
    from efish.config import EfishConfig
    from efish.physics import Scene, build_plan
    from efish.physics.fields import polarisability

    chi = PhysicsConfig().susceptibility
    assert polarisability(0.01, chi) == pytest.approx(4 * np.pi * EPS0 * 0.01**3 * chi, rel=1e-14)
    assert polarisability(0.01, chi) == pytest.approx(-5.56e-17, rel=1e-3)     # docs/model/physics.md#induction
    assert polarisability(0.0025, chi) == pytest.approx(-8.69e-19, rel=1e-3)
    radii = np.array([0.01, 0.0025])
    np.testing.assert_allclose(polarisability(radii, chi), [polarisability(0.01, chi), polarisability(0.0025, chi)],
                               rtol=1e-15)  # numpy's array power may differ from a float's in the last bit
    plan = build_plan(EfishConfig(), Scene())
    assert (plan.alpha_agent, plan.alpha_pellet) == (polarisability(0.01, chi), polarisability(0.0025, chi))
