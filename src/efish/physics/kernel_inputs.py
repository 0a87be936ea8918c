"""The fast path's kernel inputs as named structures (numba reads them as named tuples).

``DT`` below is the plan's working dtype (float32 or float64); ``B`` arenas,
``N`` agents, ``P`` pellet slots, ``I`` wall images (image 0 the identity),
``S_m`` / ``S_a`` / ``S_k`` Mormyromast / Ampullary / Knollenorgan sensors,
``L`` far-field levels holding ``Q = sum of their points`` points in all.

- :class:`PlanTables`: everything a plan fixes, built once per plan
  (:func:`efish.physics.fast.prepared_inputs`).
- :class:`BatchArrays`: the snapshots of a batch, in m and in ``DT``.
- :class:`Outputs`: the raw readings the kernels add to (zeroed by the caller).
- :class:`Arena`: one arena's agents and wall images (built in the kernel).
- :class:`Workspace`: the scratch arrays of one kernel call (allocated in the kernel):
  :class:`Bodies` and :class:`Lists` of an arena, :class:`Staging` of one agent's sources.
- :class:`SourceList`: an arena's listed sources, as each agent stages them.

Constants stay a flat ``consts`` array with named indices (``c[K]``, see
:mod:`efish.physics.kernels`): numba folds module-level indices into the code.
Importing this module loads no numba. Example::

    tables = prepared_inputs(build_plan(compose([])))  # PlanTables, cached per plan
    tables.c[K], tables.interp_m.shape                 # Coulomb constant, (sum of Q, 36)
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np


class PlanTables(NamedTuple):
    """What the kernels read from an :class:`~efish.physics.plan.EffectPlan`; built once per plan."""

    img_idx: np.ndarray      # int64[I, 2]  reflections of each image along x and y
    img_w: np.ndarray        # DT[I]  wall weight of each image
    c: np.ndarray            # DT[N_CONSTS]  constants (SI), indices in kernels (K, Q, ...)
    c32: np.ndarray          # float32[N_CONSTS]  the same, for sources evaluated in float32
    flags: np.ndarray        # int64[N_FLAGS]  effect switches, indices in kernels (DO_MORM, ...)
    sensor_trig: np.ndarray  # DT[4, max(S_m, S_a)]  cos, sin of Mormyromast (rows 0-1) and Ampullary (2-3) angles
    levels: np.ndarray       # int64[L]  points of each far-field level
    level_lcq: np.ndarray    # float64[L]  log2(C Q) of each level (C the far-field safety factor)
    level_e: np.ndarray      # float64[L]  error order (Q + 1) / 2 of each level
    far_offsets: np.ndarray  # int64[L + 1]  level l owns points far_offsets[l]:far_offsets[l + 1]
    far_points: np.ndarray   # DT[2, Q]  cos, sin of the point angles of every level
    interp_m: np.ndarray     # DT[Q, S_m]  interpolation from the points to the Mormyromast sensors
    interp_a: np.ndarray     # DT[Q, S_a]  the same to the Ampullary sensors
    cos_k: np.ndarray        # DT[S_k]  cos of the Knollenorgan angles
    sin_k: np.ndarray        # DT[S_k]  sin of the Knollenorgan angles


class BatchArrays(NamedTuple):
    """B snapshots, contiguous, positions in m (see :class:`~efish.physics.snapshot.SnapshotBatch`)."""

    agent_xy: np.ndarray      # DT[B, N, 2]  m
    heading: np.ndarray       # DT[B, N]  rad
    emitting: np.ndarray      # bool[B, N]  emits an EOD this step (and the plan allows emission)
    pellet_xy: np.ndarray     # DT[B, P, 2]  m
    pellet_phi: np.ndarray    # DT[B, P]  rad, orientation of the pellet's dipole
    pellet_alive: np.ndarray  # bool[B, P]
    width: np.ndarray         # DT[B]  m
    height: np.ndarray        # DT[B]  m


class Outputs(NamedTuple):
    """Raw readings E.n in V/m that the kernels add to; the caller zeroes them."""

    mormyromast: np.ndarray   # DT[B, N, S_m]
    ampullary: np.ndarray     # DT[B, N, S_a]
    knollenorgan: np.ndarray  # DT[B, N, N - 1, S_k]  slot j: the j-th other agent in id order
    error_bound: np.ndarray   # float64[B, N, 2]  bound of |raw - exact| per Mormyromast, Ampullary reading (V/m)


class Arena(NamedTuple):
    """One arena's agents (views into :class:`BatchArrays`) and its image table."""

    axy: np.ndarray       # DT[N, 2]  m
    heading: np.ndarray   # DT[N]  rad
    emitting: np.ndarray  # bool[N]
    img: np.ndarray       # DT[I, 5]  x offset, x sign, y offset, y sign, weight of each image


class Bodies(NamedTuple):
    """An arena's bodies: agents (first N), live pellets, inert padding; ``NB`` = N + P padded to whole SIMD blocks."""

    body: np.ndarray    # DT[N_BODY, NB]  position, polarisability and moments (rows B_* of sense_kernel)
    p_ind: np.ndarray   # DT[N, 2, NB]  per emitter: the moment it induces in every body
    angles: np.ndarray  # float64[N + P]  headings, then pellet orientations
    sin_t: np.ndarray   # float64[N + P]  their sines
    cos_t: np.ndarray   # float64[N + P]  their cosines


class Lists(NamedTuple):
    """An arena's source lists, one column per body image (``cap = NB * I``); rows ``L_*``, ``S_*`` of sources."""

    lst: np.ndarray         # float64[N_LIST, cap]  the full list
    own: np.ndarray         # int64[cap]  the agent whose own body a source is (identity image only), else NOBODY
    owner: np.ndarray       # int64[cap]  the agent whose body a source is (any image), else NOBODY
    rest: np.ndarray        # float64[N_LIST, cap]  shared mode: the sources not shared
    rest_own: np.ndarray    # int64[cap]
    rest_owner: np.ndarray  # int64[cap]
    shared: np.ndarray      # float64[N_SHARED, cap]  shared mode: the sources every agent reads densely


class Staging(NamedTuple):
    """One agent's staged sources and readings (see :func:`efish.physics.sources.gather_sources`).

    ``pad``: ``cap`` plus one SIMD block per bucket; rows ``G_*`` (:mod:`efish.physics.sources`),
    ``SX`` ... (:mod:`efish.physics.kernels`).
    """

    geo: np.ndarray       # float64[N_GEO, cap]  the agent's bounds and moments of every listed source
    in_dense: np.ndarray  # bool[cap]  listed source served by the first far level (shared mode: shared source)
    order: np.ndarray     # int64[2 cap]  bucket of each listed source, then a bucket's members
    dense: np.ndarray     # float32[N_SRC, pad]  first-level sources (shared ones first), relative to the agent
    exact: np.ndarray     # DT[N_SRC, pad]  exact sources (bucket 0), absolute positions
    far: np.ndarray       # float32[N_SRC, pad]  higher-level sources (bucket l + 1: level l), relative to the agent
    offsets: np.ndarray   # int64[L + 2]  bucket l: columns offsets[l]:offsets[l + 1] of exact / far
    sensors: np.ndarray   # DT[6, max(S_m, S_a, Q)]  sensor x, y, nx, ny; readings at the points (rows 4-5)
    points32: np.ndarray  # float32[6, Q]  point x, y, nx, ny and readings there, in float32


class SourceList(NamedTuple):
    """The listed sources of an arena that each agent stages (all of them, or the rest in shared mode)."""

    lst: np.ndarray    # float64[N_LIST, cap]  rows L_*; the first ``n`` columns are used
    own: np.ndarray    # int64[cap]  see :class:`Lists`
    owner: np.ndarray  # int64[cap]
    n: int             # listed sources
    n_shared: int      # shared sources (first columns of ``Staging.dense``); 0 unless ``shared``
    shared: bool       # shared mode: Mormyromast moments are an agent weight times T1
    bound_m: float     # bound sums of the shared sources, Mormyromast column (0 unless ``shared``)
    bound_a: float     # the same, Ampullary column
    error_m: float     # error bound of the shared sources' interpolation at any agent, Mormyromast column
    error_a: float     # the same, Ampullary column


class Workspace(NamedTuple):
    """The scratch arrays of one kernel call, sized for the fullest arena of the batch.

    Three parts, not one flat tuple: a kernel that calls others counts a
    reference (an atomic operation) for every array of every tuple it is passed,
    so each kernel gets only the parts it uses.
    """

    bodies: Bodies
    lists: Lists
    staging: Staging
