"""Shared helpers of the analysis modules: column checks, keys, angles, per-agent rates, step pairs, values per
condition.

Private: the analysis modules import these so that a check or a pairing is
written once.
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping

import numpy as np
import pandas as pd

from ..config.schema import AnalysisConfig

#: The schema's analysis parameters (docs/methods/analyses.md): the keyword defaults of the analysis functions, so that
#: a function called by hand and ``efish analyze`` (which passes the analysis settings it runs with) agree.
DEFAULTS = AnalysisConfig()
#: A quantity of the simulation that each condition records (its ``env.fps``, its arena): one number for every row,
#: or condition -> its number (``efish analyze`` passes the assay's recorded conditions this way,
#: :func:`efish.config.recorded.step_rates`). There is no default: a rate in Hz or ms per step is the run's, so the
#: caller names it.
PerCondition = float | Mapping[str, float]

EPISODE = ["condition", "episode"]
AGENT_EPISODE = ["condition", "episode", "agent"]


def require(df: pd.DataFrame, columns: Iterable[str], table: str = "table") -> None:
    """Raise ValueError with one line naming the columns ``df`` lacks."""
    if missing := sorted(set(columns) - set(df.columns)):
        raise ValueError(f"{table} lacks columns {missing}")


def nan_frame(reason: str, **values) -> pd.DataFrame:
    """One row of NaN statistics that says why (the degenerate-input contract of every analysis)."""
    return pd.DataFrame([{**values, "reason": reason}])


def or_nan_row(frame: pd.DataFrame, reason: str) -> pd.DataFrame:
    """``frame``, or, when it has no rows, one NaN row with its columns and a ``reason``: nothing to summarise."""
    if len(frame):
        return frame
    return nan_frame(reason).reindex(columns=list(dict.fromkeys([*frame.columns, "reason"])))


def value_of(value: PerCondition, condition) -> float:
    """``value`` itself, or its entry for ``condition`` (:data:`PerCondition`); a condition it lacks is one
    ValueError naming it."""
    if not isinstance(value, Mapping):
        return value
    if condition not in value:
        raise ValueError(f"no recorded value for condition {condition!r} (recorded: {', '.join(map(str, value))})")
    return value[condition]


def values_of(value: PerCondition, conditions: pd.Series) -> float | np.ndarray:
    """``value`` for each row of a ``condition`` column: the number itself, or, per condition, an array aligned with
    ``conditions`` (every condition checked by :func:`value_of`)."""
    if not isinstance(value, Mapping):
        return value
    for condition in pd.unique(conditions):
        value_of(value, condition)
    return conditions.map(value).to_numpy(np.float64)


def eod_rate(steps: pd.DataFrame, window: int = DEFAULTS.rate_window, *, fps: PerCondition) -> np.ndarray:
    """Centred rolling mean of ``eod`` over ``window`` steps x ``fps`` (steps per second, each condition's as the
    run recorded it) per agent-episode (docs/methods/analyses.md#analysis-signalling), in Hz.

    Only full windows count, so the first and last ``window // 2`` steps of an
    episode are NaN rather than biased by a shorter window. Row-aligned with ``steps``.
    """
    require(steps, [*AGENT_EPISODE, "t", "eod"], "steps table")
    order = steps[[*AGENT_EPISODE, "t", "eod"]].reset_index(drop=True).sort_values([*AGENT_EPISODE, "t"])
    rate = (order["eod"].astype(np.float64).groupby([order[k] for k in AGENT_EPISODE], sort=False)
            .transform(lambda s: s.rolling(window, center=True, min_periods=window).mean()))
    return rate.sort_index().to_numpy() * values_of(fps, steps["condition"])


def pairs(steps: pd.DataFrame, columns: Iterable[str] = ()) -> pd.DataFrame:
    """Every ordered pair (agent, partner) of distinct agents at every step, with their distance.

    Columns: condition, episode, t, agent, partner, ``x_cm``, ``y_cm`` and the extra
    ``columns`` of both agents (the partner's suffixed ``_p``), ``dx_cm``, ``dy_cm``
    (partner minus agent) and ``dist_cm``; rows sorted by pair, then t.
    """
    keep = list(dict.fromkeys([*EPISODE, "t", "agent", "x_cm", "y_cm", *columns]))
    require(steps, keep, "steps table")
    left = steps[keep]
    out = left.merge(left.rename(columns={c: f"{c}_p" for c in keep if c not in (*EPISODE, "t")}),
                     on=[*EPISODE, "t"])
    out = out[out["agent"] != out["agent_p"]].rename(columns={"agent_p": "partner"})
    out["dx_cm"] = out["x_cm_p"].to_numpy(np.float64) - out["x_cm"].to_numpy(np.float64)
    out["dy_cm"] = out["y_cm_p"].to_numpy(np.float64) - out["y_cm"].to_numpy(np.float64)
    out["dist_cm"] = np.hypot(out["dx_cm"], out["dy_cm"])
    return out.sort_values([*EPISODE, "agent", "partner", "t"]).reset_index(drop=True)


def run_ids(flag: np.ndarray, same_series: np.ndarray, t: np.ndarray) -> np.ndarray:
    """Id of each maximal run of True ``flag`` over consecutive ``t`` within one series; -1 off runs.

    ``same_series[i]`` says row i continues the series of row i - 1 (rows sorted by series, t).
    """
    flag = np.asarray(flag, dtype=bool)
    prev_flag = np.r_[False, flag[:-1]]
    contiguous = np.asarray(same_series, dtype=bool) & (np.diff(np.asarray(t), prepend=np.nan) == 1)
    start = flag & ~(prev_flag & contiguous)
    ids = np.cumsum(start) - 1
    return np.where(flag, ids, -1)


def agent_sizes(steps: pd.DataFrame) -> pd.Series:
    """Size per (condition, episode, agent): sizes are fixed within an agent-episode."""
    require(steps, [*AGENT_EPISODE, "size"], "steps table")
    return steps.groupby(AGENT_EPISODE, sort=True)["size"].first()
