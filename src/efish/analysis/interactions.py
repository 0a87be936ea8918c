"""Pairwise interactions (docs/methods/analyses.md#analysis-interactions; Fig 5K-P): per-step labels, bouts, chases and
bites.

Per step and ordered pair (agent i, partner j), ``a_i`` is i's heading minus
its bearing to j, wrapped to [-pi, pi); i *faces* j when |a_i| <= pi/4 and
*faces away* when |a_i| >= 3 pi/4. The label of (i, j) is

- ``confronting``: i faces j and j faces i;
- ``chasing``: i faces j and j faces away from i;
- ``fleeing``: i faces away from j and j faces i (the mirror of chasing);
- ``dispersing``: both face away;
- ``unaligned``: anything else;
- ``undefined``: the two centres coincide (no bearing exists) or a position
  or heading is missing.

A bout is a maximal run of consecutive steps with the pair within 10 cm;
its class is the mode of the pair's per-step classes, where chasing and
fleeing are one class (``chasing``, with a chaser and a chased).
"""

from __future__ import annotations

import numpy as np
import pandas as pd

from ..units import wrap
from ._tables import AGENT_EPISODE, DEFAULTS, EPISODE, agent_sizes, nan_frame, pairs, require, run_ids
from .stats import wilcoxon_paired

LABELS = ("confronting", "chasing", "fleeing", "dispersing", "unaligned", "undefined")
#: Bout classes, in the order that breaks ties of the mode.
BOUT_LABELS = ("confronting", "chasing", "dispersing", "unaligned", "undefined")
LABEL_COLUMNS = ["condition", "episode", "t", "agent", "x_cm", "y_cm", "heading_rad"]
BOUT_COLUMNS = ["condition", "episode", "bout", "agent", "partner", "t_start", "t_end", "n_steps", "min_dist_cm",
                "label", "chaser", "chased", "bites_by_agent", "bites_by_partner", "aggressive", "contact"]


def _labels(p: pd.DataFrame, facing_rad: float, away_rad: float) -> np.ndarray:
    """Label of each ordered pair-step of a :func:`pairs` frame from the agent's point of view."""
    bearing = np.arctan2(p["dy_cm"], p["dx_cm"])
    a_i = np.abs(wrap(p["heading_rad"].to_numpy(np.float64) - bearing))
    a_j = np.abs(wrap(p["heading_rad_p"].to_numpy(np.float64) - bearing - np.pi))
    face_i, face_j, away_i, away_j = a_i <= facing_rad, a_j <= facing_rad, a_i >= away_rad, a_j >= away_rad
    label = np.select([face_i & face_j, face_i & away_j, away_i & face_j, away_i & away_j],
                      ["confronting", "chasing", "fleeing", "dispersing"], "unaligned")
    defined = (p["dist_cm"].to_numpy() > 0) & np.isfinite(a_i) & np.isfinite(a_j)
    return np.where(defined, label, "undefined")


def label_steps(steps: pd.DataFrame, facing_rad: float = DEFAULTS.facing_rad, away_rad: float = DEFAULTS.away_rad,
                within_cm: float | None = None) -> pd.DataFrame:
    """Label every ordered pair of agents at every step (module docstring; thresholds pi/4, 3 pi/4 of
    docs/methods/analyses.md#analysis-interactions).

    Needs only condition, episode, t, agent, x_cm, y_cm, heading_rad. Returns
    condition, episode, t, agent, partner, ``dist_cm`` and ``label``; with
    ``within_cm`` only pairs at most that far apart.

    >>> steps = pd.DataFrame({"condition": "c", "episode": 0, "t": 0, "agent": [0, 1],
    ...                       "x_cm": [0.0, 5.0], "y_cm": 0.0, "heading_rad": [0.0, 0.0]})
    >>> label_steps(steps)["label"].tolist()  # 0 is behind 1, both heading +x
    ['chasing', 'fleeing']
    """
    require(steps, LABEL_COLUMNS, "steps table")
    p = pairs(steps, ["heading_rad"])
    if within_cm is not None:
        p = p[p["dist_cm"] <= within_cm]
    return p[[*EPISODE, "t", "agent", "partner", "dist_cm"]].assign(label=_labels(p, facing_rad, away_rad))


def bouts(steps: pd.DataFrame, within_cm: float = DEFAULTS.bout_cm, contact_cm: float = DEFAULTS.contact_cm,
          facing_rad: float = DEFAULTS.facing_rad, away_rad: float = DEFAULTS.away_rad) -> pd.DataFrame:
    """Bouts of every unordered pair (``agent`` < ``partner``): maximal runs of consecutive steps within ``within_cm``.

    Per bout: ``t_start`` and ``t_end`` (inclusive), ``n_steps``, ``min_dist_cm``,
    ``label`` (mode of the per-step classes, ties going to the earlier of
    :data:`BOUT_LABELS`), ``chaser``/``chased`` (the agent that chased on more
    of the chasing steps; -1 when the class is not chasing or the count is a
    tie), bites each way (``bite_target``), ``aggressive`` (any bite) and
    ``contact`` (centres ever within ``contact_cm``). A table without bouts has no rows.
    """
    require(steps, [*LABEL_COLUMNS, "bite_target"], "steps table")
    p = pairs(steps, ["heading_rad", "bite_target"])
    p = p[p["agent"] < p["partner"]].reset_index(drop=True)
    label = _labels(p, facing_rad, away_rad)
    keys = p[[*EPISODE, "agent", "partner"]]
    same = (keys == keys.shift()).all(axis=1).to_numpy()
    bout = run_ids(p["dist_cm"].to_numpy() <= within_cm, same, p["t"].to_numpy())
    inside = bout >= 0
    b = p[inside].assign(bout=bout[inside], agent_chases=label[inside] == "chasing",
                         partner_chases=label[inside] == "fleeing",
                         by_agent=p["bite_target"][inside] == p["partner"][inside],
                         by_partner=p["bite_target_p"][inside] == p["agent"][inside])
    if b.empty:
        return pd.DataFrame(columns=BOUT_COLUMNS)
    out = b.groupby("bout", sort=True).agg(
        condition=("condition", "first"), episode=("episode", "first"), agent=("agent", "first"),
        partner=("partner", "first"), t_start=("t", "min"), t_end=("t", "max"), n_steps=("t", "size"),
        min_dist_cm=("dist_cm", "min"), agent_chases=("agent_chases", "sum"),
        partner_chases=("partner_chases", "sum"), bites_by_agent=("by_agent", "sum"),
        bites_by_partner=("by_partner", "sum")).reset_index()
    symmetric = np.where(label[inside] == "fleeing", "chasing", label[inside])
    counts = np.zeros((len(out), len(BOUT_LABELS)), dtype=np.int64)
    np.add.at(counts, (b["bout"].to_numpy(), pd.Categorical(symmetric, categories=BOUT_LABELS).codes), 1)
    out["label"] = np.asarray(BOUT_LABELS)[counts.argmax(axis=1)]
    chase = (out["label"] == "chasing") & (out["agent_chases"] != out["partner_chases"])
    agent_won = out["agent_chases"] > out["partner_chases"]
    out["chaser"] = np.where(chase, np.where(agent_won, out["agent"], out["partner"]), -1)
    out["chased"] = np.where(chase, np.where(agent_won, out["partner"], out["agent"]), -1)
    out["aggressive"] = (out["bites_by_agent"] + out["bites_by_partner"]) > 0
    out["contact"] = out["min_dist_cm"] <= contact_cm
    return out[BOUT_COLUMNS]


def _with_sizes(table: pd.DataFrame, steps: pd.DataFrame, who: list[str]) -> pd.DataFrame:
    """``table`` plus ``<column>_size`` for every agent-id column in ``who`` (sizes from ``steps``)."""
    sizes = agent_sizes(steps)
    return table.assign(**{f"{c}_size": sizes.reindex(pd.MultiIndex.from_arrays(
        [table["condition"], table["episode"], table[c]])).to_numpy() for c in who})


def chase_sizes(steps: pd.DataFrame, within_cm: float = DEFAULTS.bout_cm,
                bout_table: pd.DataFrame | None = None) -> pd.DataFrame:
    """Chaser and chased of every chasing bout with their sizes and the size difference (Fig 5K,L).

    ``bout_table``: the :func:`bouts` of ``steps`` when already computed (then ``within_cm`` is unused).
    """
    b = bouts(steps, within_cm) if bout_table is None else bout_table
    b = b[b["chaser"] >= 0][[*EPISODE, "bout", "t_start", "n_steps", "chaser", "chased"]].reset_index(drop=True)
    b = _with_sizes(b, steps, ["chaser", "chased"])
    return b.assign(size_difference=b["chaser_size"] - b["chased_size"])


def bite_sizes(steps: pd.DataFrame) -> pd.DataFrame:
    """Every bite (``bite_target`` >= 0) with biter and bitten sizes and the size difference (Fig 5M,N)."""
    require(steps, [*AGENT_EPISODE, "t", "size", "bite_target"], "steps table")
    bites = steps.loc[steps["bite_target"] >= 0, [*EPISODE, "t", "agent", "bite_target"]]
    bites = bites.rename(columns={"agent": "biter", "bite_target": "bitten"}).reset_index(drop=True)
    bites = _with_sizes(bites, steps, ["biter", "bitten"])
    return bites.assign(size_difference=bites["biter_size"] - bites["bitten_size"])


def bite_timing(steps: pd.DataFrame, within_cm: float = DEFAULTS.bout_cm,
                bout_table: pd.DataFrame | None = None) -> pd.DataFrame:
    """When bites fall within their bouts (Fig 5O): one row per bite inside a bout.

    ``t_from_start`` counts steps from the bout's first step; ``phase`` =
    (t - t_start + 0.5) / n_steps lies in (0, 1) for any bout length, so a
    one-step bout puts its bite at 0.5 rather than dividing by zero.
    ``bout_table``: the :func:`bouts` of ``steps`` when already computed.
    """
    b = bouts(steps, within_cm) if bout_table is None else bout_table
    bites = bite_sizes(steps)[[*EPISODE, "t", "biter", "bitten"]]
    bites = bites.assign(agent=np.minimum(bites["biter"], bites["bitten"]),
                         partner=np.maximum(bites["biter"], bites["bitten"]))
    m = bites.merge(b[[*EPISODE, "agent", "partner", "bout", "t_start", "t_end", "n_steps", "label"]],
                    on=[*EPISODE, "agent", "partner"])
    m = m[(m["t"] >= m["t_start"]) & (m["t"] <= m["t_end"])]
    m = m.assign(t_from_start=m["t"] - m["t_start"], phase=(m["t"] - m["t_start"] + 0.5) / m["n_steps"])
    return m[[*EPISODE, "bout", "label", "biter", "bitten", "t", "t_from_start", "n_steps", "phase"]].reset_index(
        drop=True)


def bite_rate_by_class(steps: pd.DataFrame, within_cm: float = DEFAULTS.bout_cm,
                       facing_rad: float = DEFAULTS.facing_rad, away_rad: float = DEFAULTS.away_rad,
                       by: tuple[str, ...] = ("condition",)) -> pd.DataFrame:
    """Bites per pair-step by the biter's per-step label, over pairs within ``within_cm`` (Fig 5P).

    For each ordered pair-step (agent, partner) within range the agent either
    bit the partner (``bite_target`` == partner) or not; ``rate`` = bites /
    ``n_steps`` per condition (``by``: per condition and episode, claim C16's unit) and label, every label of
    :data:`LABELS` listed for each with a pair within range, NaN with a reason for a label never seen.
    """
    require(steps, [*LABEL_COLUMNS, "bite_target"], "steps table")
    keys = list(by)
    p = pairs(steps, ["heading_rad", "bite_target"])
    p = p[p["dist_cm"] <= within_cm]
    p = p.assign(label=_labels(p, facing_rad, away_rad), bit=p["bite_target"] == p["partner"])
    if p.empty:
        return nan_frame(f"no pair of agents within {within_cm} cm", **dict.fromkeys(keys, np.nan), label=np.nan,
                         n_steps=0, bites=0, rate=np.nan)
    seen = p[keys].drop_duplicates().sort_values(keys).itertuples(index=False, name=None)
    grid = pd.MultiIndex.from_tuples([(*unit, label) for unit in seen for label in LABELS], names=[*keys, "label"])
    out = p.groupby([*keys, "label"])["bit"].agg(n_steps="size", bites="sum").reindex(grid, fill_value=0)
    out = out.reset_index()
    out["rate"] = np.divide(out["bites"], out["n_steps"], out=np.full(len(out), np.nan), where=out["n_steps"] > 0)
    out["reason"] = np.where(out["n_steps"] > 0, "", "label never seen within range")
    return out


def label_counts(steps: pd.DataFrame, facing_rad: float = DEFAULTS.facing_rad,
                 away_rad: float = DEFAULTS.away_rad) -> pd.DataFrame:
    """The ethogram (Fig 3A): ordered pair-steps per condition and :func:`label_steps` label, and their fraction.

    Every label of :data:`LABELS` is listed per condition, zeros included; an
    empty table (or a lone agent) gives one NaN row with a reason.
    """
    labels = label_steps(steps, facing_rad, away_rad)
    if labels.empty:
        return nan_frame("no pair of agents", condition=np.nan, label=np.nan, n_steps=0, fraction=np.nan)
    grid = pd.MultiIndex.from_product([sorted(labels["condition"].unique()), LABELS], names=["condition", "label"])
    out = labels.groupby(["condition", "label"]).size().reindex(grid, fill_value=0).rename("n_steps").reset_index()
    out["fraction"] = out["n_steps"] / out.groupby("condition")["n_steps"].transform("sum")
    return out.assign(reason="")


def size_role_tests(chases: pd.DataFrame, bites: pd.DataFrame) -> pd.DataFrame:
    """Is the chaser larger than the chased, the biter than the bitten? Wilcoxon signed-rank per condition.

    ``chases`` and ``bites`` are :func:`chase_sizes` and :func:`bite_sizes`
    tables; each chasing bout or bite is one pair. Rows of
    :mod:`efish.analysis.stats` (group ``chaser`` vs control ``chased``, effect
    the median size difference) with ``measure`` (``chase`` or ``bite``) and ``condition``.
    """
    parts = []
    for measure, table, role, other in (("chase", chases, "chaser", "chased"), ("bite", bites, "biter", "bitten")):
        for cond, sub in list(table.groupby("condition", sort=True)) or [(np.nan, table)]:
            long = pd.concat([pd.DataFrame({"pair": np.arange(len(sub)), "role": r,
                                            "size": sub[f"{r}_size"].to_numpy(np.float64)}) for r in (role, other)])
            parts.append(wilcoxon_paired(long, "size", "role", other, "pair").assign(measure=measure, condition=cond))
    return pd.concat(parts, ignore_index=True)
