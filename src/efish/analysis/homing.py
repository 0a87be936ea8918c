"""Homing (docs/methods/assays.md#assay-homing; Fig 2B-D): error angles and trajectory shape, electric vs ray-casting.

The rollout writes, per homer step, the error angle between its heading and
the local direction of the target's field seen by each receptor class
(``err_morm_rad``, ``err_amp_rad``, ``err_knollen_rad``); steps where a class
sees nothing are NaN and are left out here.
"""

from __future__ import annotations

import numpy as np
import pandas as pd
from scipy import stats as sps

from ..senses import SENSES, error_column
from ..units import wrap
from ._tables import AGENT_EPISODE, DEFAULTS, nan_frame, or_nan_row, require
from .stats import mann_whitney, spearman

#: Receptor class (its short spelling, the ``channel``) -> error-angle column of the steps table.
ERROR_COLUMNS = {sense.short: error_column(sense) for sense in SENSES}
SHAPE_MEASURES = ("tortuosity", "curvature_rad_per_cm", "path_length_cm", "n_steps")
#: Columns of :func:`alignment_episodes` (docs/methods/analyses.md#analysis-homing).
ALIGNMENT_COLUMNS = [*AGENT_EPISODE, "channel", "success", "n_steps", "aligned_fraction", "straight_aligned_fraction",
                     "aligned_excess", "alignment_rho", "reason"]


def error_angles(steps: pd.DataFrame) -> pd.DataFrame:
    """Long table of error angles: condition, episode, agent, t, ``t_norm``, ``channel``, ``err_rad``.

    ``t_norm`` = (t - first t) / (last t - first t) of the agent-episode, so 0
    is the start and 1 the end however long the episode ran (a one-step
    episode sits at 0). Uses whichever ``err_*_rad`` columns exist (at least one).
    """
    present = {ch: col for ch, col in ERROR_COLUMNS.items() if col in steps.columns}
    if not present:
        raise ValueError(f"steps table lacks every error-angle column {sorted(ERROR_COLUMNS.values())}")
    require(steps, [*AGENT_EPISODE, "t"], "steps table")
    t = steps["t"].to_numpy(np.float64)
    g = steps.groupby(AGENT_EPISODE, sort=False)["t"]
    t0, t1 = g.transform("min").to_numpy(np.float64), g.transform("max").to_numpy(np.float64)
    base = steps[[*AGENT_EPISODE, "t"]].assign(t_norm=(t - t0) / np.maximum(t1 - t0, 1.0))
    long = pd.concat([base.assign(channel=ch, err_rad=wrap(steps[col].to_numpy(np.float64)))
                      for ch, col in present.items()], ignore_index=True)
    return long[np.isfinite(long["err_rad"])].reset_index(drop=True)


def error_histogram(steps: pd.DataFrame, bins: int = 36) -> pd.DataFrame:
    """Polar histogram of error angles on ``bins`` equal bins of [-pi, pi), per condition and channel (Fig 2C).

    ``density`` is per radian, so it integrates to 1 over the circle.
    """
    long = error_angles(steps)
    edges = np.linspace(-np.pi, np.pi, bins + 1)
    parts = []
    for (cond, ch), sub in long.groupby(["condition", "channel"], sort=True):
        counts, _ = np.histogram(sub["err_rad"], bins=edges)
        parts.append(pd.DataFrame({"condition": cond, "channel": ch, "bin_lo_rad": edges[:-1],
                                   "bin_hi_rad": edges[1:], "count": counts,
                                   "density": counts / (counts.sum() * np.diff(edges))}))
    if not parts:
        return nan_frame("no finite error angle", condition=np.nan, channel=np.nan, count=0, density=np.nan)
    return pd.concat(parts, ignore_index=True).assign(reason="")


def error_vs_time(steps: pd.DataFrame, bins: int = 10) -> pd.DataFrame:
    """Error angle against normalised time in ``bins`` equal bins (Fig 2D), per condition and channel.

    Per bin: ``n`` steps, mean and SEM of |error| (rad), and the circular mean
    of the signed error (scipy.stats.circmean). Bins without steps are absent.
    """
    long = error_angles(steps)
    long["bin"] = np.minimum((long["t_norm"] * bins).astype(np.int64), bins - 1)
    long["abs_err_rad"] = long["err_rad"].abs()
    g = long.groupby(["condition", "channel", "bin"], sort=True)
    out = g["abs_err_rad"].agg(n="size", mean_abs_err_rad="mean", sem_abs_err_rad="sem").reset_index()
    out["circmean_err_rad"] = wrap(g["err_rad"].agg(lambda e: sps.circmean(e, high=np.pi, low=-np.pi)).to_numpy())
    out["t_norm_mid"] = (out["bin"] + 0.5) / bins
    return or_nan_row(out.assign(reason=""), "no finite error angle")


def alignment_episodes(steps: pd.DataFrame, aligned_rad: float = DEFAULTS.claims_aligned_rad) -> pd.DataFrame:
    """How each agent-episode's error angles align with the target's field (Fig 2C,D; claims C2 and C3): one row per
    agent-episode and receptor class with a finite error angle (columns :data:`ALIGNMENT_COLUMNS`).

    Over its ``n_steps`` steps with a finite error angle: ``aligned_fraction``, the fraction whose error is within
    ``aligned_rad`` of 0 or pi (|cos err| > cos ``aligned_rad``); ``straight_aligned_fraction``, the same for a
    homer heading straight at the target from the same positions (error + ``bearing_agent_rad``, the geometric null;
    a step without a bearing counts as not aligned); ``aligned_excess``, the first minus the second;
    ``alignment_rho``, the Spearman rho of |sin err| against normalised time (:func:`error_angles`; negative: the
    angle aligns over the episode), NaN with a ``reason`` under 3 steps or when either is constant. ``success``:
    the agent-episode reached its goal (on any of its steps).
    """
    require(steps, [*AGENT_EPISODE, "t", "bearing_agent_rad", "success"], "steps table")
    keys = [*AGENT_EPISODE, "channel"]
    err = error_angles(steps).merge(steps[[*AGENT_EPISODE, "t", "bearing_agent_rad"]], on=[*AGENT_EPISODE, "t"])
    straight = err["err_rad"] + err["bearing_agent_rad"]
    err = err.assign(observed=np.abs(np.cos(err["err_rad"])) > np.cos(aligned_rad),
                     straight=np.abs(np.cos(straight)) > np.cos(aligned_rad), abs_sin=np.abs(np.sin(err["err_rad"])))
    g = err.groupby(keys, sort=True)
    out = g.agg(n_steps=("t", "size"), aligned_fraction=("observed", "mean"),
                straight_aligned_fraction=("straight", "mean")).reset_index()
    out["aligned_excess"] = out["aligned_fraction"] - out["straight_aligned_fraction"]
    rho = spearman(err.assign(unit=g.ngroup()), "t_norm", "abs_sin", by="unit").set_index("group")
    out["alignment_rho"] = rho["effect"].reindex(out.index).to_numpy(np.float64)
    out["reason"] = rho["reason"].reindex(out.index).fillna("").to_numpy()
    success = steps.groupby(AGENT_EPISODE, sort=True)["success"].any()
    out["success"] = success.reindex(pd.MultiIndex.from_frame(out[AGENT_EPISODE])).to_numpy(bool)
    return or_nan_row(out[ALIGNMENT_COLUMNS], "no finite error angle")


def trajectory_shape(steps: pd.DataFrame) -> pd.DataFrame:
    """Path length, start-to-end displacement, tortuosity and curvature per agent-episode (Fig 2B).

    ``tortuosity`` = path length / displacement (1 for a straight path);
    ``curvature_rad_per_cm`` = total absolute heading change / path length.
    Both are NaN with a reason for an agent that did not move (e.g. the frozen
    target) or ended where it started. ``success`` and ``t_end`` say how the
    episode ended when the table has a ``success`` column.
    """
    require(steps, [*AGENT_EPISODE, "t", "x_cm", "y_cm", "heading_rad"], "steps table")
    frame = steps.sort_values([*AGENT_EPISODE, "t"])
    same = frame.duplicated(AGENT_EPISODE, keep="first").to_numpy()  # True for every row but an episode's first
    xy, heading = frame[["x_cm", "y_cm"]].to_numpy(np.float64), frame["heading_rad"].to_numpy(np.float64)
    step = np.where(same, np.hypot(*np.diff(xy, axis=0, prepend=xy[:1]).T), 0.0)
    turn = np.where(same, np.abs(wrap(np.diff(heading, prepend=heading[:1]))), 0.0)
    frame = frame.assign(step_cm=step, turn_rad=turn, missing=~np.all(np.isfinite(np.c_[xy, heading]), axis=1))
    g = frame.groupby(AGENT_EPISODE, sort=True)
    out = g.agg(n_steps=("t", "size"), t_end=("t", "max"), path_length_cm=("step_cm", "sum"),
                total_turn_rad=("turn_rad", "sum"), x0=("x_cm", "first"), y0=("y_cm", "first"),
                x1=("x_cm", "last"), y1=("y_cm", "last"), n_missing=("missing", "sum")).reset_index()
    if "success" in frame:
        out["success"] = g["success"].any().to_numpy()
    out["displacement_cm"] = np.hypot(out["x1"] - out["x0"], out["y1"] - out["y0"])
    complete = out["n_missing"] == 0
    moved, apart = complete & (out["path_length_cm"] > 0), complete & (out["displacement_cm"] > 0)
    out["tortuosity"] = np.divide(out["path_length_cm"], out["displacement_cm"], out=np.full(len(out), np.nan),
                                  where=moved & apart)
    out["curvature_rad_per_cm"] = np.divide(out["total_turn_rad"], out["path_length_cm"],
                                            out=np.full(len(out), np.nan), where=moved)
    out.loc[~complete, ["path_length_cm", "total_turn_rad", "displacement_cm"]] = np.nan
    out["reason"] = np.select([~complete, ~moved, ~apart],
                              ["missing position or heading", "agent did not move", "start and end coincide"], "")
    return out.drop(columns=["x0", "y0", "x1", "y1", "n_missing"])


def compare_perception(steps: pd.DataFrame, electric: str = "electric", raycasting: str | None = "raycasting",
                       agent: int | None = None) -> pd.DataFrame:
    """Mann-Whitney tests of trajectory shape, ray-casting vs electric (Fig 2B), one row per measure.

    ``electric`` and ``raycasting`` are the two condition names; ``raycasting=None``
    compares every other condition with ``electric`` (none: NaN rows that say
    so). ``agent`` keeps only the homer. Rows are :mod:`efish.analysis.stats` rows plus ``measure``.
    """
    shape = trajectory_shape(steps)
    if agent is not None:
        shape = shape[shape["agent"] == agent]
    if raycasting is not None:
        shape = shape[shape["condition"].isin([electric, raycasting])]
        if raycasting not in set(shape["condition"]):
            raise ValueError(f"condition {raycasting!r} is not in the steps table")
    return pd.concat([mann_whitney(shape, m, "condition", electric).assign(measure=m) for m in SHAPE_MEASURES],
                     ignore_index=True)
