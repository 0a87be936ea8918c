"""What the steps table records about each agent at each step, beyond the state itself: the inputs of the
analyses (docs/methods/analyses.md), Fig 6's targets among them (docs/methods/analyses.md#decoding-variables).

Functions of an env's state after a step (or of the observation the step
returned): distances and bearings to the nearest bodies, the sizes of the
nearest agents, food counts near the agent by sector, the realised turn, how
many conspecifics the Knollenorgans hear and how many are within Knollenorgan
range, log10 of the Mormyromast reading as sensed, and the physics quantities
the analyses must not recompute (error angles of a homer against its target's
local fields; log10 of the Mormyromast- and Ampullary-relevant fields at the
body centre). Every function returns arrays [B, N] keyed by their column names
(or one such array).

The pairwise measures (nearest bodies, food counts, agents in range, the
fields) loop over arena, agent and body in the numba kernels of
:mod:`efish.rollout.measure_kernels`: they run at every step of an assay, and
the numpy formulas, kept in :mod:`efish.rollout.measures_reference` as their
tested twin, cost more than the simulation itself.

The fields are the physics' own: the formulas of :mod:`efish.physics.fields`, the
EOD monopoles and intrinsic moments of :mod:`efish.physics.reference`, and the
constants (charges, moments, polarisabilities) of the env's effect plan, so a
recorded field cannot drift from the simulated one.
"""

from __future__ import annotations

import numpy as np

from ..env.vec_env import VecEnv
from ..physics.fields import coulomb_constant, induced_dipole, pairwise_dipole_field, pairwise_monopole_field
from ..physics.plan import EffectPlan
from ..physics.reference import eod_monopoles, intrinsic_moments
from ..senses import SENSES, error_column
from ..units import CM, wrap
from .measure_kernels import (
    FieldConstants,
    count_within,
    food_sectors,
    log_fields_kernel,
    nearest_agents,
    nearest_food,
    nearest_wall,
)

SECTORS = ("front", "left", "back", "right")  # bearing within pi/4 of 0, pi/2, pi, -pi/2


def nearest(env: VecEnv) -> dict[str, np.ndarray]:
    """Distance (cm) and bearing (rad, from the heading) to the nearest agent, pellet and wall; the distance to
    the second-nearest agent and the sizes of the nearest two (NaN where there is none)."""
    s = env.state
    shape = s.heading.shape
    out = {key: np.empty(shape) for key in ("dist_agent_cm", "bearing_agent_rad", "size_agent1", "size_agent2",
                                             "dist_agent2_cm", "dist_food_cm", "bearing_food_rad", "dist_wall_cm",
                                             "bearing_wall_rad")}
    nearest_agents(s.xy, s.heading, s.size, out["dist_agent_cm"], out["bearing_agent_rad"], out["dist_agent2_cm"],
                   out["size_agent1"], out["size_agent2"])
    nearest_food(s.xy, s.heading, s.pellet_xy, s.alive, out["dist_food_cm"], out["bearing_food_rad"])
    nearest_wall(s.xy, s.heading, s.width, s.height, out["dist_wall_cm"], out["bearing_wall_rad"])
    return out


def food_counts(env: VecEnv, radius_cm: float = 5.0) -> dict[str, np.ndarray]:
    """Live pellets within ``radius_cm`` of each agent, in all and per sector of the bearing from the heading."""
    s = env.state
    counts = np.empty((1 + len(SECTORS), *s.heading.shape), np.int64)   # all, then one row per sector
    food_sectors(s.xy, s.heading, s.pellet_xy, s.alive, float(radius_cm), counts)
    return {"food_count_5cm": counts[0], **{f"food_{name}_5cm": counts[1 + k] for k, name in enumerate(SECTORS)}}


def knollen_agents(knollen_block: np.ndarray, slots: int) -> np.ndarray:
    """Conspecifics heard: slots of the Knollenorgan observation block [B, N, slots * K] with any spike."""
    b, n, width = knollen_block.shape
    return (knollen_block.reshape(b, n, slots, width // slots) != 0).any(-1).sum(-1)


def agents_in_range(env: VecEnv, range_cm: float) -> np.ndarray:
    """Other agents whose centre is closer than ``range_cm`` to each agent's centre (int [B, N]).

    The authors' "agents in Knollenorgan range" decoding target (a strict
    ``<``, as theirs): a count of the world around the agent, whether or not
    those agents emitted on the step (:func:`knollen_agents` counts those
    heard, which also depends on their EODs).
    """
    counts = np.empty(env.state.heading.shape, np.int64)
    count_within(env.state.xy, float(range_cm), counts)
    return counts


def log_morm_sensed(morm_block: np.ndarray, e_min: float, e_max: float) -> np.ndarray:
    """log10 (V/m) of the strongest Mormyromast reading each agent sensed, from its observation block [B, N, M].

    The reading is the one the channel delivers: after the baseline
    subtraction (the own and conspecific direct EODs removed, so
    it holds the self image only when the agent emitted, and the gained
    conspecific image otherwise), with the sensor noise, clipped to
    [``e_min``, ``e_max``]. The log normalisation (efish.sensors.normalize) is inverted:
    log10 |s| = log10 e_min + |y| (log10 e_max - log10 e_min) where y != 0.
    NaN where no sensor reads above ``e_min`` (y = 0 everywhere: nothing is
    sensed, and the true value is only known to be below e_min; decoding drops
    these rows rather than invent a value). A saturated sensor gives log10 e_max.

    Why the largest reading: the authors decode log10 |E| of the baseline-
    subtracted field vector at the body centre, a point without a sensor
    (``mormyromast_field_mag_log`` from ``center_field``, KempnerInstitute/wef
    analysis_rnn_decoding.py and sensing.py). On the ring of sensors, whose
    normals span every direction, the largest |E.n| is that magnitude up to
    the sensors' angular spacing (at most 11.1 deg, so >= 0.995 of it for a
    uniform field) and the field's variation over the 1 cm radius; any one
    sensor (e.g. the chin's) reads only the component along its normal. Unlike
    the authors' centre vector, this carries the channel's noise, clipping and
    the x k_cons gain of a silent agent: it is what the policy received.
    """
    y = np.abs(np.asarray(morm_block, dtype=np.float64)).max(axis=-1)
    lo, hi = np.log10(e_min), np.log10(e_max)
    return np.where(y > 0, lo + y * (hi - lo), np.nan)


def eod_field(plan: EffectPlan, softening_m: float, xy_m: np.ndarray, heading: np.ndarray,
              at_m: np.ndarray) -> np.ndarray:
    """Direct EOD field (V/m) of emitters at ``xy_m`` [..., 2] with ``heading`` [...] at points ``at_m`` [..., 2]
    (broadcast): the physics' two EOD monopoles of each emitter (efish.physics.reference.eod_monopoles), summed."""
    positions, charges = eod_monopoles(xy_m, heading, plan)            # [..., 2 monopoles, 2], (2,)
    e = pairwise_monopole_field(at_m[..., None, :], positions, charges, softening=softening_m, eps0=plan.eps0)
    return e.sum(axis=-2)


def angle_of(e: np.ndarray) -> np.ndarray:
    """Direction (rad) of vectors ``e`` [..., 2]."""
    return np.arctan2(e[..., 1], e[..., 0])


def homing_errors(env: VecEnv) -> dict[str, np.ndarray]:
    """Heading minus the direction of the target's local field at each homer, per receptor class (Fig 2C,
    docs/methods/figures.md#panels).

    Knollenorgan: the target's direct EOD field; Ampullary: its intrinsic dipole's
    field; Mormyromast: the field of the dipole the homer's own EOD induces on
    the target (the homer taken as emitting: a property of the geometry). Free
    space (no wall images), at the homer's centre. NaN for the target itself and
    in tasks without a target.
    """
    s, plan, soft = env.state, env.plan, env.cfg.physics.softening_m
    shape = s.heading.shape
    target = getattr(env.task, "target", None)
    if target is None or not target.any():
        return {error_column(sense): np.full(shape, np.nan) for sense in SENSES}
    t = int(np.flatnonzero(target)[0])
    xy, h = s.xy * CM, s.heading
    txy, th = xy[:, t:t + 1], h[:, t:t + 1]                           # [B, 1, 2], [B, 1]
    field = {"softening": soft, "eps0": plan.eps0}
    e_knollen = eod_field(plan, soft, txy, th, xy)
    p_intrinsic = intrinsic_moments(th, np.empty((len(th), 0)), plan)  # the target's own dipole [B, 1, 2]; no pellets
    e_amp = pairwise_dipole_field(xy, txy, p_intrinsic, **field)
    p_induced = induced_dipole(plan.alpha_agent, eod_field(plan, soft, xy, h, txy))  # in the target, per homer
    e_morm = pairwise_dipole_field(xy, txy, p_induced, **field)
    out = {}
    for sense, e in zip(SENSES, (e_morm, e_amp, e_knollen), strict=True):
        err = wrap(h - angle_of(e))
        err[:, t] = np.nan
        out[error_column(sense)] = err
    return out


def log_fields(env: VecEnv) -> dict[str, np.ndarray]:
    """log10 |E| (V/m) at each agent's centre of what each electroreceptor class senses (decoding targets).

    Ampullary: the intrinsic dipoles of every other body; Mormyromast: the
    dipoles the agent's own EOD induces on every other body. Free space, live
    pellets only; -inf where the field is exactly 0.
    """
    s, plan, soft = env.state, env.plan, env.cfg.physics.softening_m
    consts = FieldConstants(k=coulomb_constant(plan.eps0), eod_charge=plan.eod_charge,
                            half_sep=plan.eod_half_separation, agent_dipole=plan.agent_dipole,
                            pellet_dipole=plan.pellet_dipole, alpha_agent=plan.alpha_agent,
                            alpha_pellet=plan.alpha_pellet, soft2=soft * soft)
    out = {"log_amp_field": np.empty(s.heading.shape), "log_morm_field": np.empty(s.heading.shape)}
    log_fields_kernel(s.xy * CM, s.heading, s.pellet_xy * CM, s.pellet_phi, s.alive, consts,
                      out["log_amp_field"], out["log_morm_field"])
    return out
