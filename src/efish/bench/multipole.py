"""``efish bench multipole``: would cell multipoles make the far field of large arenas cheaper?

The fast path reads every far source directly at the Q points of the first
far-field level (:mod:`efish.physics.sense_kernel`), so its cost grows with the
pellets. The textbook alternative sums the sources of a cell into a Cartesian
multipole and evaluates that instead. This benchmark measures whether it pays
at the plan's accuracy, in one run:

1. what one cell costs at one point, per order p, against one source read by
   the fast path's own far-field kernel (:func:`efish.physics.kernels.far_readings`),
   both moment columns in float32;
2. how many cells a quadtree needs around each agent of a scaling scene when
   every cell keeps its truncation bound below the same ``tolerance x E_min``
   a single source must (Ampullary column, the longest-reaching one: pellets'
   intrinsic dipoles and all their wall images), and what reading them would
   cost against reading every source directly.

The expansion: a dipole m at c + delta read at point p with normal n gives
n . grad grad (1/rho)(p - c - delta) m, rho^2 = |.|^2 + eps^2, so a cell
contributes sum over multi-indices a of n . grad grad d^a (1/rho)(p - c) M_a with
M_a = sum_j (-delta_j)^a / a! m_j. Directional derivatives of 1/r of order n are
at most n! / r^(n+1) (as for 3-D Coulomb: 1/rho is 1/r at height eps), so the
Taylor remainder of order p is at most
(p + 3)(p + 2) rho_c^(p+1) sum|m| / (D - rho_c)^(p+4), with rho_c the cell's radius
and D the distance from the point to its centre (:func:`truncation_bound`).
The expansion here is a measuring instrument, not part of the fast path.
"""

from __future__ import annotations

from math import factorial

import numpy as np
import pandas as pd

from .._jit import njit
from ..config.schema import EfishConfig
from ..physics import kernels as kn
from ..physics.fast import prepared_inputs
from ..physics.kernel_inputs import PlanTables
from ..physics.sources import L_A2, L_X, L_Y, N_LIST, list_images
from ..units import CM
from .scaling import ScalingCase, case_config, stepper
from .timing import best_time

CELLS_TIMED = 1024   # cells (or sources) per timed call: long enough loops for SIMD, small enough for the cache
LEAF_SOURCES = 16    # a quadtree cell with at most this many sources is read source by source
MIN_SIDE = 1e-9      # m: a smaller cell is not split again (sources on one spot would split it forever)


def multi_indices(order: int) -> list[tuple[int, int]]:
    """The (a, b) with a + b <= order, by total order: the terms of a 2-D expansion of that order."""
    return [(a, n - a) for n in range(order + 1) for a in range(n + 1)]


@njit(cache=True, fastmath=True, error_model="numpy")
def coulomb_derivatives(x, y, soft2, order, out):
    """out[t, u, k] = d^t/dx^t d^u/dy^u of 1 / sqrt(x^2 + y^2 + soft2) at (x[k], y[k]), for t + u <= order.

    The Hermite recurrence of Coulomb integrals: R^n_00 = (-1)^n (2n - 1)!! / rho^(2n+1),
    R^n_(t+1)u = t R^(n+1)_(t-1)u + x R^(n+1)_tu (likewise in y), and the derivatives are R^0.
    Cells are the innermost loop, so each step vectorises.
    """
    cells = x.shape[0]
    r = np.empty((order + 1, order + 1, order + 1, cells), x.dtype)  # [n, t, u, cell]
    for k in range(cells):
        inv2 = 1.0 / (x[k] * x[k] + y[k] * y[k] + soft2)
        f = np.sqrt(inv2)
        for n in range(order + 1):
            r[n, 0, 0, k] = f
            f = -f * (2 * n + 1) * inv2
    for n in range(order - 1, -1, -1):
        for s in range(1, order - n + 1):  # total order s at level n, from level n + 1
            for t in range(s + 1):
                u = s - t
                if t > 0:
                    for k in range(cells):
                        v = x[k] * r[n + 1, t - 1, u, k]
                        if t > 1:
                            v += (t - 1) * r[n + 1, t - 2, u, k]
                        r[n, t, u, k] = v
                else:
                    for k in range(cells):
                        v = y[k] * r[n + 1, 0, u - 1, k]
                        if u > 1:
                            v += (u - 1) * r[n + 1, 0, u - 2, k]
                        r[n, 0, u, k] = v
    for t in range(order + 1):
        for u in range(order + 1 - t):
            out[t, u] = r[0, t, u]


def cell_moments(dx: np.ndarray, dy: np.ndarray, mx: np.ndarray, my: np.ndarray, order: int) -> np.ndarray:
    """M[i, 0/1] = sum_j (-dx_j)^a (-dy_j)^b / (a! b!) (mx_j, my_j) for the i-th (a, b) of :func:`multi_indices`.

    dx, dy: the sources' offsets from the cell centre; mx, my: their moments.
    """
    rows = []
    for a, b in multi_indices(order):
        g = (-dx) ** a * (-dy) ** b / (factorial(a) * factorial(b))
        rows.append([(g * mx).sum(), (g * my).sum()])
    return np.array(rows)


@njit(cache=True, fastmath=True, error_model="numpy")
def multipole_readings(x, y, soft2, moments, nx, ny, order, deriv, out):
    """out[col, k] = n . E at a point of cell k's expansion, both moment columns.

    x, y: the point minus each cell's centre; moments[i, col, 0/1, k]: cell k's
    M of the i-th multi-index (:func:`multi_indices` of ``order``); deriv: scratch
    (order + 3, order + 3, cells) for :func:`coulomb_derivatives`.
    """
    coulomb_derivatives(x, y, soft2, order + 2, deriv)
    out[:] = 0.0
    i = 0
    for n in range(order + 1):
        for a in range(n + 1):
            b = n - a
            for k in range(x.shape[0]):
                dxx, dxy, dyy = deriv[a + 2, b, k], deriv[a + 1, b + 1, k], deriv[a, b + 2, k]
                for col in range(2):
                    mx, my = moments[i, col, 0, k], moments[i, col, 1, k]
                    out[col, k] += nx * (dxx * mx + dxy * my) + ny * (dxy * mx + dyy * my)
            i += 1


def truncation_bound(order: int, radius: float, distance: float, moment_sum: float) -> float:
    """Bound of the order-``order`` remainder of a cell of ``radius`` read at ``distance`` from its centre
    (both in m; ``moment_sum``: sum of the sources' |m|, k folded in): (p+3)(p+2) rho^(p+1) sum|m| / (D - rho)^(p+4)."""
    gap = distance - radius
    if gap <= 0:
        return float("inf")
    return (order + 3) * (order + 2) * radius ** (order + 1) * moment_sum / gap ** (order + 4)


def quadtree_cost(xy: np.ndarray, moment: np.ndarray, agent: np.ndarray, threshold: float, order: int,
                  sensor_radius: float, box: tuple[float, float, float]) -> tuple[int, int, int]:
    """(cells, sources in them, direct sources) of a quadtree over the sources ``xy`` (m) for the agent at ``agent``.

    Starting from the square ``box`` (x0, y0, side), a cell whose truncation bound
    at the agent's sensor circle stays at or below ``threshold`` is evaluated as
    one expansion; a cell of at most ``LEAF_SOURCES`` sources, or too small to
    split further (coinciding sources), is read source by source; any other
    cell is split in four.
    """
    cells = in_cells = direct = 0
    stack = [(box, np.arange(len(xy)))]
    while stack:
        (x0, y0, side), members = stack.pop()
        if len(members) == 0:
            continue
        if len(members) <= LEAF_SOURCES or side < MIN_SIDE:
            direct += len(members)
            continue
        radius = side / np.sqrt(2.0)
        distance = float(np.hypot(x0 + side / 2 - agent[0], y0 + side / 2 - agent[1])) - sensor_radius
        if truncation_bound(order, radius, distance, float(moment[members].sum())) <= threshold:
            cells += 1
            in_cells += len(members)
            continue
        half = side / 2
        right, top = xy[members, 0] >= x0 + half, xy[members, 1] >= y0 + half
        for qx, qy, pick in ((x0, y0, ~right & ~top), (x0 + half, y0, right & ~top),
                             (x0, y0 + half, ~right & top), (x0 + half, y0 + half, right & top)):
            stack.append(((qx, qy, half), members[pick]))
    return cells, in_cells, direct


def _direct_ns(c32: np.ndarray, points: int, rng: np.random.Generator, repeats: int) -> float:
    """ns per source and point of the fast path's far-field kernel over ``CELLS_TIMED`` sources (constants ``c32``)."""
    src = np.zeros((kn.N_SRC, CELLS_TIMED), np.float32)
    src[[kn.SX, kn.SY]] = rng.uniform(0.5, 3.0, (2, CELLS_TIMED))
    src[[kn.M1X, kn.M1Y, kn.M2X, kn.M2Y]] = rng.normal(size=(4, CELLS_TIMED))
    angles = np.linspace(0, 2 * np.pi, points, endpoint=False)
    nx, ny = np.cos(angles).astype(np.float32), np.sin(angles).astype(np.float32)
    qx, qy = c32[kn.R_SENS] * nx, c32[kn.R_SENS] * ny
    out1, out2 = np.zeros(points, np.float32), np.zeros(points, np.float32)
    seconds = best_time(lambda: kn.far_readings(src, 0, CELLS_TIMED, qx, qy, nx, ny, c32, out1, out2), repeats)
    return seconds / (CELLS_TIMED * points) * 1e9


def _cell_ns(soft2: np.float32, order: int, rng: np.random.Generator, repeats: int) -> float:
    """ns per cell and point of :func:`multipole_readings` of ``order`` over ``CELLS_TIMED`` cells, float32."""
    x, y = rng.uniform(0.5, 3.0, (2, CELLS_TIMED)).astype(np.float32)
    moments = rng.normal(size=(len(multi_indices(order)), 2, 2, CELLS_TIMED)).astype(np.float32)
    deriv = np.zeros((order + 3, order + 3, CELLS_TIMED), np.float32)
    out = np.zeros((2, CELLS_TIMED), np.float32)
    seconds = best_time(lambda: multipole_readings(x, y, soft2, moments, np.float32(0.6),
                                                   np.float32(0.8), order, deriv, out), repeats)
    return seconds / CELLS_TIMED * 1e9


def _scene_sources(cfg: EfishConfig, width_cm: float) -> tuple[np.ndarray, np.ndarray, np.ndarray, tuple, PlanTables]:
    """Every pellet image of one arena of a scaling scene after a few random steps, as the fast path lists them
    (:func:`efish.physics.sources.list_images`): positions (m) and Ampullary |moment| (k and wall weight folded
    in); the agents (m), a box holding every image, and the plan's kernel tables."""
    case = ScalingCase("pellets", f"{width_cm:g}x{width_cm:g}", width_cm, cfg.bench.scaling_n_agents,
                       cfg.arena.food_multiplier)
    run, _, env = stepper(case_config(cfg, case), 1, 4 * case.n_agents, cfg.bench.seed)
    run()
    batch = env.snapshot(np.zeros((1, case.n_agents), bool))
    tables = prepared_inputs(env.plan)
    c, side = tables.c, width_cm * CM
    pellets = batch.pellet_xy[0][batch.pellet_alive[0]] * CM
    phi = batch.pellet_orientation[0][batch.pellet_alive[0]]
    m2 = c[kn.K] * c[kn.P_PELLET]
    img = kn.image_table(side, side, tables.img_idx, tables.img_w, c)
    count = len(pellets) * img.shape[0]
    lst, own, owner = np.empty((N_LIST, count)), np.empty(count, np.int64), np.empty(count, np.int64)
    list_images(pellets[:, 0].copy(), pellets[:, 1].copy(), -m2 * np.sin(phi), m2 * np.cos(phi), img, 0, lst, own,
                owner)
    xy = np.ascontiguousarray(lst[[L_X, L_Y]].T)
    lo, hi = xy.min(axis=0), xy.max(axis=0)
    box = (float(lo[0]), float(lo[1]), float((hi - lo).max()) * (1 + 1e-9))
    return xy, lst[L_A2].copy(), batch.agent_xy[0] * CM, box, tables


def bench_multipole(cfg: EfishConfig, orders: tuple[int, ...] | None = None, width_cm: float | None = None,
                    repeats: int = 20) -> pd.DataFrame:
    """One row per (order, agent): the measured per-point costs and the quadtree's cells and cost at that agent.
    ``orders`` and ``width_cm`` default to ``bench.multipole_orders`` and ``bench.multipole_width_cm``.

    Columns: order, agent, cell_ns (per cell and point), direct_ns (per source and
    point), cells, direct_sources, sources, quadtree_us and direct_us (one agent's
    Ampullary far field at the first far level's points, from those costs).
    """
    orders = tuple(cfg.bench.multipole_orders if orders is None else orders)
    width_cm = cfg.bench.multipole_width_cm if width_cm is None else width_cm
    if not orders or min(orders) < 0:
        raise ValueError(f"orders must be non-negative and at least one, got {list(orders)}")
    if width_cm <= 0:
        raise ValueError(f"width_cm must be positive, got {width_cm}")
    rng = np.random.default_rng(cfg.bench.seed)
    points = int(cfg.physics.far_field_levels[0]) if cfg.physics.far_field_levels else 1
    xy, moment, agents, box, tables = _scene_sources(cfg, width_cm)
    threshold, r = float(tables.c[kn.TOL_AMP]), float(tables.c[kn.R_SENS])
    direct_ns = _direct_ns(tables.c32, points, rng, repeats)
    rows = []
    for order in orders:
        cell_ns = _cell_ns(tables.c32[kn.SOFT2], order, rng, repeats)
        for a, agent in enumerate(agents):
            cells, _, direct = quadtree_cost(xy, moment, agent, threshold, order, r, box)
            rows.append({"order": order, "agent": a, "cell_ns": cell_ns, "direct_ns": direct_ns, "cells": cells,
                         "direct_sources": direct, "sources": len(xy),
                         "quadtree_us": (cells * cell_ns + direct * direct_ns) * points / 1e3,
                         "direct_us": len(xy) * direct_ns * points / 1e3})
    return pd.DataFrame(rows)


def format_multipole(df: pd.DataFrame) -> str:
    """A table per order (ranges over the agents) and the verdict."""
    header = (f"{'order':>5} {'ns/cell-point':>13} {'= sources':>9} {'cells':>9} {'direct':>11} "
              f"{'quadtree us':>12} {'direct us':>9}")
    lines = [header]
    for order, g in df.groupby("order"):
        lines.append(f"{order:>5} {g.cell_ns.iloc[0]:>13.1f} {g.cell_ns.iloc[0] / g.direct_ns.iloc[0]:>9.0f} "
                     f"{g.cells.min():>4}-{g.cells.max():<4} {g.direct_sources.min():>5}-{g.direct_sources.max():<5} "
                     f"{g.quadtree_us.min():>5.0f}-{g.quadtree_us.max():<6.0f} {g.direct_us.iloc[0]:>9.0f}")
    best = df.groupby("order").quadtree_us.max().min()
    lines.append(f"direct far field: {df.direct_ns.iloc[0]:.2f} ns per source and point, {df.sources.iloc[0]} sources; "
                 f"the best order's worst agent needs {best / df.direct_us.iloc[0]:.2f}x the direct time")
    return "\n".join(lines)
