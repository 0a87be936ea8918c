"""Python side of the fast path: plan -> :class:`PlanTables` (once per plan), batch -> raw readings."""

from __future__ import annotations

import weakref

import numpy as np

from ..units import CM
from . import kernels as kn
from .far_field import flat_far_tables, level_tables
from .kernel_inputs import BatchArrays, Outputs, PlanTables
from .plan import EffectPlan
from .readings import RawReadings, empty_readings
from .sense_kernel import sense_batch_kernel
from .snapshot import SnapshotBatch


def kernel_constants(plan: EffectPlan) -> tuple[np.ndarray, np.ndarray]:
    """The ``consts`` (working dtype) and ``flags`` (int64) arrays the kernels read."""
    dtype = np.dtype(plan.dtype)
    c = np.zeros(kn.N_CONSTS, dtype=np.float64)
    c[kn.K], c[kn.Q], c[kn.HALF_SEP] = plan.k, plan.eod_charge, plan.eod_half_separation
    c[kn.P_AGENT], c[kn.P_PELLET] = plan.agent_dipole, plan.pellet_dipole
    c[kn.ALPHA_AGENT], c[kn.ALPHA_PELLET] = plan.alpha_agent, plan.alpha_pellet
    c[kn.SOFT2], c[kn.R_SENS] = plan.softening2, plan.sensor_radius
    c[kn.TOL_MORM] = plan.tolerance * plan.morm_range[0]
    c[kn.TOL_AMP] = plan.tolerance * plan.amp_range[0]
    # A whole array is exactly 0 after normalisation when its bound, times the noise, is <= E_min.
    c[kn.ZERO_MORM] = plan.morm_range[0] / plan.max_noise
    c[kn.ZERO_AMP] = plan.amp_range[0] / plan.max_amp_noise
    c[kn.KNOLL_ZERO] = plan.knollen_threshold / plan.max_noise
    c[kn.G_SELF], c[kn.G_CONS], c[kn.K_CONS] = plan.g_self, plan.g_cons, plan.k_cons
    c[kn.ONE], c[kn.TWO], c[kn.THREE], c[kn.ZERO] = 1.0, 2.0, 3.0, 0.0
    # log2(r / D) above this: the source is too close to interpolate
    c[kn.FAR_MAX_LX] = np.log2(plan.sensor_radius / plan.far_min) if plan.far_levels else -np.inf
    # Interpolated sources are evaluated in float32: keep its round-off (~eps * bound) at or
    # below the threshold, i.e. bound / threshold <= 1 / eps; stronger sources stay exact.
    c[kn.FAR_MAX_LS] = np.log2(1.0 / np.finfo(np.float32).eps)
    f = np.zeros(kn.N_FLAGS, dtype=np.int64)
    f[kn.DO_MORM] = plan.on("mormyromast") and (plan.on("induction") or plan.on("wall_distortion"))
    f[kn.DO_AMP] = plan.on("ampullary") and plan.on("intrinsic_fields")
    f[kn.DO_KNOLL] = plan.on("knollenorgan")
    f[kn.DO_INDUCTION] = plan.on("induction")
    f[kn.DO_WALLDIST] = plan.on("wall_distortion")
    f[kn.DO_PELLETS] = plan.on("pellets")
    f[kn.CULL] = plan.tolerance > 0
    f[kn.ERROR_BOUND] = plan.on("error_bound")
    return c.astype(dtype), f


_PREPARED: "weakref.WeakKeyDictionary[EffectPlan, PlanTables]" = weakref.WeakKeyDictionary()


def prepared_inputs(plan: EffectPlan) -> PlanTables:
    """Everything the batch kernel needs from a plan, in the kernel dtype; built once per plan."""
    if plan not in _PREPARED:
        dtype = np.dtype(plan.dtype)

        def arr(x):
            return np.ascontiguousarray(np.asarray(x, dtype=np.float64), dtype=dtype)

        c, flags = kernel_constants(plan)
        angles = (plan.morm_angles, plan.amp_angles)
        trig = np.zeros((4, max(len(a) for a in angles)))
        for row, a in enumerate(angles):
            trig[2 * row, :len(a)], trig[2 * row + 1, :len(a)] = np.cos(a), np.sin(a)
        level_lcq, level_e = level_tables(plan)
        far_offsets, far_points, interp_m, interp_a = flat_far_tables(plan)
        _PREPARED[plan] = PlanTables(
            img_idx=plan.image_indices, img_w=arr(plan.image_weights), c=c, c32=c.astype(np.float32), flags=flags,
            sensor_trig=arr(trig), levels=np.array(plan.far_levels, dtype=np.int64), level_lcq=level_lcq,
            level_e=level_e, far_offsets=far_offsets, far_points=arr(far_points), interp_m=arr(interp_m),
            interp_a=arr(interp_a), cos_k=arr(np.cos(plan.knollen_angles)), sin_k=arr(np.sin(plan.knollen_angles)))
    return _PREPARED[plan]


def fast_raw(batch: SnapshotBatch, plan: EffectPlan) -> RawReadings:
    """Raw readings of every receptor of every agent with the numba kernels, in ``plan.dtype``."""
    dtype = np.dtype(plan.dtype)
    b, n, _ = batch.shape
    out = empty_readings(b, n, plan, dtype)
    error_bound = np.zeros((b, n, 2))  # the kernel fills it when asked; all zero when no field is computed
    out.error_bound = error_bound if plan.on("error_bound") else None
    if not plan.on("fields"):
        return out
    tables = prepared_inputs(plan)
    if not (tables.flags[kn.DO_MORM] or tables.flags[kn.DO_AMP] or tables.flags[kn.DO_KNOLL]):
        return out

    def arr(x, scale=None):  # the input itself when it already fits; scaled in float64, then cast
        if scale is None:
            return np.ascontiguousarray(x, dtype=dtype)
        scaled = np.multiply(x, scale, dtype=np.float64, order="C")
        return scaled if dtype == np.float64 else scaled.astype(dtype)

    arrays = BatchArrays(
        agent_xy=arr(batch.agent_xy, CM), heading=arr(batch.agent_heading),
        emitting=np.ascontiguousarray(batch.agent_emitting & plan.on("eod_emission")),
        pellet_xy=arr(batch.pellet_xy, CM), pellet_phi=arr(batch.pellet_orientation),
        pellet_alive=np.ascontiguousarray(batch.pellet_alive), width=arr(batch.width, CM), height=arr(batch.height, CM))
    outputs = Outputs(out.mormyromast, out.ampullary, out.knollenorgan, error_bound)
    sense_batch_kernel(tuple(arrays), tuple(tables), tuple(outputs))  # plain tuples pass faster, see the kernel
    return out
