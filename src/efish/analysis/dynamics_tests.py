"""Tests on the hidden-state dynamics (docs/methods/analyses.md#analysis-dynamics; Fig 6B, I, J): D_eff against group
size, wideband power by context.

The dynamics analysis writes them as statistic tables (columns of
:data:`efish.analysis.stats.STAT_COLUMNS` plus ``measure``): ``size_tests``
(Spearman of D_eff against the group size N, separately with Knollenorgans on
and off, each condition's N and Knollenorgan state read from the config the
run recorded for it, whatever the condition is called: the groupsize assay,
``config/assay/groupsize.yaml``, or a user's assay that varies ``env.n_agents``) and ``power_tests`` (wideband power with the nearest
conspecific near vs far, Wilcoxon over agent-episodes; of the smallest agent of
an episode vs the others, Mann-Whitney). Fig 6 and the claims C17 and C21 read
these rows.
"""

from __future__ import annotations

from collections.abc import Mapping

import numpy as np
import pandas as pd

from ..config.schema import EfishConfig
from ._tables import AGENT_EPISODE, EPISODE, PerCondition, agent_sizes, nan_frame, require, value_of
from .dynamics import _with_steps, degenerate_reason, units, wideband_power
from .stats import mann_whitney, nan_stat_row, spearman, wilcoxon_paired

NEAR_FAR_COLUMNS = [*AGENT_EPISODE, "where", "n_steps", "wideband_power", "reason"]
#: A Knollenorgan state's group label in the tables: on (``K``) or off (``noK``).
KNOLLENORGAN_GROUPS = {True: "K", False: "noK"}


def group_settings(conditions: Mapping[str, EfishConfig]) -> pd.DataFrame:
    """Each recorded condition's group size ``n_agents`` (``env.n_agents``) and ``knollenorgans`` (``K`` when
    ``sensors.knollenorgan.enabled``, else ``noK``), as the run simulated it
    (:func:`efish.config.recorded.recorded_conditions`)."""
    return pd.DataFrame({"condition": list(conditions),
                         "n_agents": [int(c.env.n_agents) for c in conditions.values()],
                         "knollenorgans": [KNOLLENORGAN_GROUPS[bool(c.sensors.knollenorgan.enabled)]
                                           for c in conditions.values()]})


def groupsize_parts(table: pd.DataFrame, conditions: Mapping[str, EfishConfig]) -> pd.DataFrame:
    """The rows of ``table`` with their condition's ``n_agents`` (N) and ``knollenorgans`` (``K`` or ``noK``) from
    :func:`group_settings`, in the table's order; rows of a condition the run did not record are dropped."""
    require(table, ["condition"], "table")
    settings = group_settings(conditions)
    clash = [c for c in ("n_agents", "knollenorgans") if c in table.columns]
    return table.drop(columns=clash).merge(settings, on="condition", how="inner", validate="many_to_one")


def size_tests(dims: pd.DataFrame, conditions: Mapping[str, EfishConfig]) -> pd.DataFrame:
    """Spearman rho of D_eff against group size N over agent-episodes, one row per Knollenorgan state (group K, noK).

    ``dims``: the dimensionality table (:func:`efish.analysis.dynamics.dynamics_table`); ``conditions``: the assay's
    recorded conditions, which give each condition's N and Knollenorgan state. An assay whose conditions all have
    one group size gets one NaN row that says so.
    """
    require(dims, ["condition", "d_eff"], "dimensionality table")
    frame = groupsize_parts(dims, conditions)
    if frame["n_agents"].nunique() < 2:
        sizes = sorted(frame["n_agents"].unique().tolist())
        return nan_stat_row(f"the group size (env.n_agents) does not vary across the conditions: {sizes}",
                            measure="d_eff")
    return spearman(frame, "n_agents", "d_eff", by="knollenorgans").assign(measure="d_eff")


def power_near_far(hidden: pd.DataFrame, steps: pd.DataFrame, near_cm: float, far_cm: float, window: int,
                   overlap: int, fps: PerCondition) -> pd.DataFrame:
    """Wideband power per agent-episode over its steps with the nearest conspecific near (<= ``near_cm``) and far
    (> ``far_cm``), at its condition's ``fps``: one row per agent-episode and ``where``; NaN power (with a reason)
    when too few steps."""
    if far_cm < near_cm:
        raise ValueError(f"far_cm ({far_cm}) must not be below near_cm ({near_cm})")
    j, h = _with_steps(hidden, steps, ["dist_agent_cm"]), units(hidden)
    rows = []
    for keys, sub in j.groupby(AGENT_EPISODE, sort=True):
        d = sub["dist_agent_cm"].to_numpy(np.float64)
        x = sub[h].to_numpy(np.float64)  # rows in t order (_with_steps sorts)
        fs = value_of(fps, keys[0])
        for where, keep in (("near", d <= near_cm), ("far", d > far_cm)):
            rows.append({**dict(zip(AGENT_EPISODE, keys, strict=True)), "where": where, "n_steps": int(keep.sum()),
                         "wideband_power": wideband_power(x[keep], window, overlap, fs=fs),
                         "reason": (f"only {keep.sum()} {where} steps, fewer than the {window}-step spectrogram "
                                    "window" if keep.sum() < window else degenerate_reason(x[keep], window))})
    return pd.DataFrame(rows, columns=NEAR_FAR_COLUMNS)


def smaller_larger(dims: pd.DataFrame, steps: pd.DataFrame) -> pd.DataFrame:
    """The dimensionality rows with ``role`` ``smaller`` (the smallest agent of its episode) or ``larger``;
    episodes whose agents all have one size are left out."""
    d = dims.drop(columns="size", errors="ignore").merge(agent_sizes(steps).rename("size").reset_index(),
                                                         on=AGENT_EPISODE)
    by = d.groupby(EPISODE)["size"]
    mixed = (by.transform("nunique") > 1).to_numpy()
    role = np.where(by.rank(method="min") == 1, "smaller", "larger")
    return d.assign(role=role)[mixed]


#: Columns of :func:`power_roles` (docs/methods/analyses.md#analysis-dynamics).
ROLE_COLUMNS = [*AGENT_EPISODE, "size", "role", "wideband_power", "reason"]


def power_roles(dims: pd.DataFrame, steps: pd.DataFrame) -> pd.DataFrame:
    """The wideband power of every agent-episode in an episode whose agents differ in size, with its ``size`` and
    ``role`` (:func:`smaller_larger`; claim C21), columns :data:`ROLE_COLUMNS`; one NaN row that says why when there
    is none."""
    require(dims, [*AGENT_EPISODE, "wideband_power", "reason"], "dimensionality table")
    roles = smaller_larger(dims, steps)[ROLE_COLUMNS]
    return roles if len(roles) else nan_frame("no episode with agents of different sizes").reindex(columns=ROLE_COLUMNS)


def power_tests(near_far: pd.DataFrame, dims: pd.DataFrame, steps: pd.DataFrame) -> pd.DataFrame:
    """Wideband power far minus near (Wilcoxon, paired by agent-episode; measure ``near_far``) and smaller minus
    larger agent (Mann-Whitney over agent-episodes; measure ``size``)."""
    require(dims, [*AGENT_EPISODE, "wideband_power"], "dimensionality table")
    out = []
    pairs = near_far.dropna(subset=["wideband_power"])
    if set(pairs["where"]) >= {"near", "far"}:
        out.append(wilcoxon_paired(pairs, "wideband_power", "where", "near", AGENT_EPISODE).assign(measure="near_far"))
    else:
        out.append(nan_stat_row("no agent-episode with enough near and far steps for a spectrogram", group="far",
                            control="near", measure="near_far"))
    roles = smaller_larger(dims, steps).dropna(subset=["wideband_power"])
    if set(roles["role"]) >= {"smaller", "larger"}:
        out.append(mann_whitney(roles, "wideband_power", "role", "larger").assign(measure="size"))
    else:
        out.append(nan_stat_row("no episode with agents of different sizes and a finite wideband power",
                            group="smaller", control="larger", measure="size"))
    return pd.concat(out, ignore_index=True)
