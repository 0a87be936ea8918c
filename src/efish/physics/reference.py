"""Brute-force reference of the raw receptor readings: the oracle for tests and accuracy studies.

Every source and every wall image is evaluated at every sensor with the
vectorised formulas of :mod:`efish.physics.fields`; nothing is culled. Written
for clarity, not speed: it is never used for training.
"""

from __future__ import annotations

import numpy as np

from ..units import CM
from .fields import dipole_field, induced_dipole, monopole_field
from .geometry import conspecific_slots, sensor_frame
from .images import image_sources
from .plan import EffectPlan
from .readings import RawReadings, empty_readings
from .snapshot import SnapshotBatch


def eod_monopoles(xy: np.ndarray, heading: np.ndarray, plan: EffectPlan) -> tuple[np.ndarray, np.ndarray]:
    """Positions [..., 2, 2] m and charges (2,) C of the EODs of emitters at ``xy`` [..., 2] m with ``heading``
    [...]: +q ahead, -q behind (axis -2 is the monopole). One emitter: positions (2, 2)."""
    heading = np.asarray(heading)
    u = np.stack([np.cos(heading), np.sin(heading)], axis=-1) * plan.eod_half_separation
    return np.stack([xy + u, xy - u], axis=-2), np.array([plan.eod_charge, -plan.eod_charge])


def intrinsic_moments(heading: np.ndarray, pellet_phi: np.ndarray, plan: EffectPlan) -> np.ndarray:
    """Intrinsic dipoles (C*m) [..., N + P, 2] of N agents with ``heading`` [..., N], along body +x, then of P
    pellets with orientation ``pellet_phi`` [..., P], along pellet +y, i.e. (-sin phi, cos phi) in world
    coordinates (docs/model/physics.md#field-sources)."""
    heading, pellet_phi = np.asarray(heading), np.asarray(pellet_phi)
    return np.concatenate([plan.agent_dipole * np.stack([np.cos(heading), np.sin(heading)], axis=-1),
                           plan.pellet_dipole * np.stack([-np.sin(pellet_phi), np.cos(pellet_phi)], axis=-1)],
                          axis=-2)


def _normal_component(e: np.ndarray, normals: np.ndarray) -> np.ndarray:
    return np.einsum("si,si->s", e, normals)


def reference_raw(batch: SnapshotBatch, plan: EffectPlan) -> RawReadings:
    """Raw readings of every receptor of every agent, all sources, no culling (float64)."""
    b_count, n, _ = batch.shape
    out = empty_readings(b_count, n, plan)
    out.morm_self = np.zeros_like(out.mormyromast)
    out.morm_cons = np.zeros_like(out.mormyromast)
    if not plan.on("fields"):
        return out
    for b in range(b_count):
        _reference_env(batch, b, plan, out)
    return out


def _reference_env(batch: SnapshotBatch, b: int, plan: EffectPlan, out: RawReadings) -> None:
    n = batch.shape[1]
    w, h = batch.width[b] * CM, batch.height[b] * CM
    soft, eps0 = np.sqrt(plan.softening2), plan.eps0
    idx, scale = plan.image_indices, plan.image_scale
    xy = batch.agent_xy[b] * CM
    heading = batch.agent_heading[b]
    emitting = batch.agent_emitting[b] & plan.on("eod_emission")
    alive = batch.pellet_alive[b] & plan.on("pellets")
    pxy, phi = batch.pellet_xy[b][alive] * CM, batch.pellet_orientation[b][alive]
    bodies = np.concatenate([xy, pxy])                       # agents first, then pellets
    alpha = np.concatenate([np.full(n, plan.alpha_agent), np.full(len(pxy), plan.alpha_pellet)])

    # Induced dipoles, kept per emitter: p_ind[body, emitter] (docs/model/physics.md#induction).
    p_ind = np.zeros((len(bodies), n, 2))
    if plan.on("induction"):
        for e in np.flatnonzero(emitting):
            pos, q = eod_monopoles(xy[e], heading[e], plan)
            ipos, _, wq = image_sources(pos, None, w, h, idx, scale)
            e_at = monopole_field(bodies, ipos, np.tile(q, len(idx)) * wq, softening=soft, eps0=eps0)
            p_ind[:, e] = induced_dipole(alpha, e_at, own=e)

    p_int = intrinsic_moments(heading, phi, plan)

    def dipoles_at(points, normals, positions, moments, skip_identity=False):
        ipos, imom, _ = image_sources(positions, moments, w, h, idx, scale)
        if skip_identity:
            ipos, imom = ipos[len(positions):], imom[len(positions):]
        if len(ipos) == 0:
            return np.zeros(len(points))
        return _normal_component(dipole_field(points, ipos, imom, softening=soft, eps0=eps0), normals)

    for a in range(n):
        others = np.arange(len(bodies)) != a
        if plan.on("mormyromast"):
            s_pos, s_n = sensor_frame(xy[a], heading[a], plan.morm_angles, plan.sensor_radius)
            if plan.on("induction"):
                self_part = dipoles_at(s_pos, s_n, bodies[others], p_ind[others, a])
                cons_m = p_ind[others].sum(axis=1) - p_ind[others, a]
                cons_part = dipoles_at(s_pos, s_n, bodies[others], cons_m)
            else:
                self_part = cons_part = np.zeros(len(s_pos))
            if plan.on("wall_distortion") and emitting[a]:
                pos, q = eod_monopoles(xy[a], heading[a], plan)
                ipos, _, wq = image_sources(pos, None, w, h, idx, scale)
                e = monopole_field(s_pos, ipos[2:], (np.tile(q, len(idx)) * wq)[2:], softening=soft, eps0=eps0)
                self_part = self_part + _normal_component(e, s_n)
            c = plan.k_cons if (not emitting[a] or plan.g_self == 0) else 1.0
            out.morm_self[b, a], out.morm_cons[b, a] = self_part, cons_part
            out.mormyromast[b, a] = plan.g_self * self_part + plan.g_cons * c * cons_part
        if plan.on("ampullary") and plan.on("intrinsic_fields"):
            s_pos, s_n = sensor_frame(xy[a], heading[a], plan.amp_angles, plan.sensor_radius)
            # others in free space and with images; the own dipole only through its images
            out.ampullary[b, a] = (dipoles_at(s_pos, s_n, bodies[others], p_int[others])
                                   + dipoles_at(s_pos, s_n, bodies[a:a + 1], p_int[a:a + 1], skip_identity=True))
        if plan.on("knollenorgan"):
            s_pos, s_n = sensor_frame(xy[a], heading[a], plan.knollen_angles, plan.sensor_radius)
            for slot, j in enumerate(conspecific_slots(n)[a]):
                if emitting[j]:
                    pos, q = eod_monopoles(xy[j], heading[j], plan)
                    e = monopole_field(s_pos, pos, q, softening=soft, eps0=eps0)
                    out.knollenorgan[b, a, slot] = _normal_component(e, s_n)
