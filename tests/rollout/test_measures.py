"""The physics quantities the steps table records (efish.rollout.measures): the physics' own fields at known
points, and known directions of a homer's error angles."""

from __future__ import annotations

import numpy as np
import pytest

from efish.config import compose
from efish.env.vec_env import VecEnv
from efish.physics.fields import dipole_field, monopole_field
from efish.physics.reference import eod_monopoles
from efish.rollout.measures import eod_field, homing_errors, log_fields
from efish.units import CM


@pytest.fixture(scope="module")
def foraging_env():
    """Two arenas of four foraging agents with pellets, reset."""
    env = VecEnv(compose(["arena=patchy70"]), num_envs=2, seed=5)
    env.reset()
    return env


@pytest.fixture(scope="module")
def homing_env():
    env = VecEnv(compose(["env=homing", "arena=uniform70"]), num_envs=1, seed=2)
    env.reset()
    return env


def test_the_eod_field_is_the_physics_field_of_the_two_monopoles(foraging_env):
    plan, soft = foraging_env.plan, foraging_env.cfg.physics.softening_m
    xy, heading = np.array([0.2, 0.3]), 0.7
    points = np.random.default_rng(0).uniform(0.0, 0.7, (6, 2))
    positions, charges = eod_monopoles(xy, heading, plan)
    expected = monopole_field(points, positions, charges, softening=soft, eps0=plan.eps0)
    np.testing.assert_allclose(eod_field(plan, soft, xy, np.array(heading), points), expected, rtol=1e-13)
    # emitters broadcast against points: a [3, 6] batch of pairs
    many = eod_field(plan, soft, np.broadcast_to(xy, (3, 1, 2)), np.full((3, 1), heading), points[None])
    assert many.shape == (3, 6, 2)
    np.testing.assert_allclose(many[2], expected, rtol=1e-13)


def _brute_force_log_fields(env: VecEnv, b: int, i: int) -> tuple[float, float]:
    """log10 |E_amp| and |E_morm| at agent ``i`` of arena ``b``, from the physics' summed fields, body by body."""
    s, plan, soft = env.state, env.plan, env.cfg.physics.softening_m
    ph = env.cfg.physics
    xy = s.xy[b] * CM
    others = [j for j in range(env.n) if j != i]
    pellets = np.flatnonzero(s.alive[b])
    bodies = np.concatenate([xy[others], s.pellet_xy[b, pellets] * CM])
    phi = s.pellet_phi[b, pellets]
    p_int = np.concatenate([ph.agent_dipole_coulomb_metre * np.c_[np.cos(s.heading[b, others]), np.sin(s.heading[b, others])],
                            ph.pellet_dipole_coulomb_metre * np.c_[-np.sin(phi), np.cos(phi)]])
    e_amp = dipole_field(xy[i:i + 1], bodies, p_int, softening=soft, eps0=plan.eps0)[0]
    positions, charges = eod_monopoles(xy[i], s.heading[b, i], plan)
    e_own = monopole_field(bodies, positions, charges, softening=soft, eps0=plan.eps0)       # own EOD at each body
    alpha = np.r_[np.full(len(others), plan.alpha_agent), np.full(len(pellets), plan.alpha_pellet)]
    e_morm = dipole_field(xy[i:i + 1], bodies, alpha[:, None] * e_own, softening=soft, eps0=plan.eps0)[0]
    return np.log10(np.linalg.norm(e_amp)), np.log10(np.linalg.norm(e_morm))


def test_log_fields_are_the_physics_fields_of_every_other_live_body(foraging_env):
    out = log_fields(foraging_env)
    assert out["log_amp_field"].shape == out["log_morm_field"].shape == (2, 4)
    assert foraging_env.state.alive.any(axis=1).all(), "the fixture should hold pellets"
    for b in range(2):
        for i in range(4):
            amp, morm = _brute_force_log_fields(foraging_env, b, i)
            assert out["log_amp_field"][b, i] == pytest.approx(amp, abs=1e-12)
            assert out["log_morm_field"][b, i] == pytest.approx(morm, abs=1e-12)


@pytest.mark.parametrize(("homer_heading", "errors"), [
    (np.pi, {"knollen": 0.0, "amp": 0.0, "morm": np.pi}),
    (0.0, {"knollen": np.pi, "amp": np.pi, "morm": np.pi}),
])
def test_homing_errors_at_the_targets_broadside_have_known_directions(homing_env, homer_heading, errors):
    """Target (agent 0) at the arena centre facing +x, the homer 10 cm to its left (broadside). There, the target's
    EOD and intrinsic dipole fields point against its moment, -x. The homer's own EOD points against the homer's
    heading at the target, the dipole it induces there points along that heading (chi < 0), and that dipole's field
    back at the homer against it again: the Mormyromast error is pi whichever way the homer faces."""
    s = homing_env.state
    s.xy[0, 0], s.heading[0, 0] = (35.0, 35.0), 0.0
    s.xy[0, 1], s.heading[0, 1] = (35.0, 45.0), homer_heading
    out = homing_errors(homing_env)
    for name, err in errors.items():
        got = out[f"err_{name}_rad"][0]
        assert np.isnan(got[0])  # the target itself
        assert np.cos(got[1]) == pytest.approx(np.cos(err), abs=1e-9), name  # pi and -pi are one direction


def test_homing_errors_are_nan_without_a_target(foraging_env):
    out = homing_errors(foraging_env)
    assert set(out) == {"err_morm_rad", "err_amp_rad", "err_knollen_rad"}
    assert all(np.isnan(v).all() and v.shape == (2, 4) for v in out.values())
