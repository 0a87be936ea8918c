"""Decoding world variables from hidden states (docs/methods/analyses.md#analysis-dynamics; Fig 6D-F, claims C18
and C19): the one decoder and the one list of decoded variables.

:func:`heldout_skill` is the decoder: a linear readout fitted on whole
episodes and scored on each held-out episode. :func:`decode_episodes` applies
it to every target of :data:`DECODE_TARGETS` per condition (the dynamics
table ``decoding_episodes``) and :func:`summarise` pools its errors over the
episodes (``decoding``, the bars of Fig 6D,E); :func:`food_decode_episodes`
does the same on the steps with food near and far (``food_decoding_episodes``
and ``food_decoding``, Fig 6F). The claims C18 and C19 read these tables, so
a panel and a claim rest on the same numbers.
"""

from __future__ import annotations

import numpy as np
import pandas as pd

from ._tables import DEFAULTS, nan_frame
from .dynamics import _with_steps, units

#: Steps columns of the world the agent senses (docs/methods/analyses.md#decoding-variables) -> circular (radians)
#: or not: the variables ranked against each other (Fig 6D,E), among which claim C19 takes its competitors. Each
#: describes the world after step t, which the hidden row t has taken in (efish.rollout.run.hidden_table); none is
#: computed from the observation itself (``log_morm_field``, the field the own EOD induces on the other bodies at
#: the body centre, is computed from the scene). The homing error angles are NaN outside homing.
SENSED_TARGETS = {"dist_agent_cm": False, "bearing_agent_rad": True, "dist_agent2_cm": False, "size_agent1": False,
                  "size_agent2": False, "n_agents_100cm": False, "dist_food_cm": False, "bearing_food_rad": True,
                  "food_count_5cm": False, "dist_wall_cm": False, "bearing_wall_rad": True, "log_amp_field": False,
                  "log_morm_field": False, "err_knollen_rad": True, "err_morm_rad": True, "err_amp_rad": True}
#: Distances decoded as log10 of the distance, the scale of the fields the agent senses them by: a dipole's field
#: falls as a power of the distance, so the recorded fields (``log_amp_field``, ``log_morm_field``) and the
#: network's log-normalised sensor inputs are linear in the log of a distance, not in the distance, and a linear
#: readout of centimetres would score the shape of that curve rather than what the state carries (the third
#: audit). Every distance the rollout records is positive (bodies keep their radius from walls and from each
#: other); a distance <= 0 has no log and is left out, as a NaN is.
LOG_DISTANCES = ("dist_agent_cm", "dist_agent2_cm", "dist_food_cm", "dist_wall_cm")
#: Steps columns that are copies of the decoded network's own input (docs/claims/index.md#rule-7): the turn and EOD
#: of step t (its last action, fed back in the observation row t's state takes in), the agent's own size (in every
#: observation), and two summaries computed from the observation of step t alone (the Knollenorgan inputs that
#: spike; the largest Mormyromast input, log-scaled back to V/m). Decoding them measures how the input passes into
#: the state, not what the state makes of the world: decoded and reported, never ranked among the sensed targets.
READOUT_TARGETS = {"turn_rad": False, "eod": False, "size": False, "knollen_spikes": False,
                   "log_morm_sensed": False}
#: Every decoded steps column -> circular: the sensed targets, then the readouts. A column the steps table lacks
#: gets a row with a reason, so that the decoding tables have a row for each.
DECODE_TARGETS = {**SENSED_TARGETS, **READOUT_TARGETS}
#: The food variables decoded separately with food near and far (Fig 6F, claim C19) -> circular or not.
FOOD_TARGETS = {c: SENSED_TARGETS[c] for c in ("dist_food_cm", "bearing_food_rad")}

#: Columns of :func:`heldout_skill`: one row per held-out group (episode).
SKILL_COLUMNS = ["episode", "n", "sse", "sse_mean", "skill", "folds", "reason"]
#: Columns of :func:`decode_episodes` (dynamics ``decoding_episodes``): one row per condition, target and episode.
DECODED_COLUMNS = ["condition", "target", "circular", "readout", *SKILL_COLUMNS]
#: Columns of :func:`summarise` (dynamics ``decoding``): one row per condition and target.
SUMMARY_COLUMNS = ["condition", "target", "circular", "readout", "skill", "episode_skill_median", "n_episodes", "n",
                   "folds", "reason"]


def heldout_skill(x: np.ndarray, y: np.ndarray, groups: np.ndarray, circular: bool = False,
                  folds: int = DEFAULTS.decode_folds) -> pd.DataFrame:
    """Held-out decoding skill of ``y`` from ``x`` per group (episode): 1 - SSE(readout) / SSE(training mean).

    The readout is OLS with an intercept (sklearn LinearRegression) fitted
    under GroupKFold(``folds``) over ``groups``: each group is held out whole,
    once, and predicted by the fit on the other folds. On each held-out group
    ``g``, ``sse`` = sum_g |readout - y|^2, ``sse_mean`` = sum_g |training mean
    - y|^2 with that fold's training mean, and skill = 1 - sse / sse_mean: 1
    for a perfect readout, 0 for one no better than the mean, below 0 for a
    worse one. A circular ``y`` (radians) is the unit vector (cos y, sin y)
    and its squared error the squared chord between the angles. Rows with a
    non-finite value are dropped.

    Why this score (the claims' held-out skill), kept over the R^2 minus
    baseline R^2 that Fig 6 used before (pooled over the folds; the authors
    average it over folds, KempnerInstitute/wef analysis_rnn_decoding.py):

    - one number per episode, so that two targets can be compared paired over
      the unit of every claim test (docs/claims/index.md#rule-1); the errors
      it is made of add up to the pooled skill a panel draws
      (:func:`summarise`), where a pooled R^2 gives no number per episode;
    - its baseline is the same prediction R^2 - baseline R^2 subtracts, but
      it is in units of that baseline's error, so that 1 is a perfect readout
      whatever the held-out episodes' means (the difference of R^2s exceeds 1
      when their means differ from the training mean);
    - an angle's error is the distance between unit vectors, the same wherever
      the angle's zero lies; R^2 averaged over cos and sin weighs a component
      that hardly varies (a bearing near 0 has sin near 0) as much as one that
      carries the angle.

    Both put whole episodes in folds, so no step is predicted by a fit on its own
    episode's neighbours; the authors' folds hold out agent-episodes, so that
    two agents of one episode, who share its world, can fall on both sides.

    One row per group with a finite row (columns :data:`SKILL_COLUMNS`, ``n``
    its rows, ``folds`` the folds used); fewer than 2 groups or a constant
    target: one row, group NaN, with the reason. A group whose target the
    training mean predicts exactly has no skill (NaN) and says so.
    """
    return heldout_skills(x, {"y": (y, circular)}, groups, folds)["y"]


def heldout_skills(x: np.ndarray, targets: dict[str, tuple[np.ndarray, bool]], groups: np.ndarray,
                   folds: int = DEFAULTS.decode_folds) -> dict[str, pd.DataFrame]:
    """:func:`heldout_skill` of several targets from the same ``x`` and ``groups``: name -> (values, circular) in,
    name -> its table out, in the same order.

    Targets whose finite rows are the same have the same folds, and OLS fits each output column on its own, so
    they share each fold's fit: one least-squares solve with their columns side by side instead of one per target
    (the decoding tables' twenty-odd targets, five folds each, were most of a dynamics job). Each target's
    readout is the one it would get alone, to rounding.
    """
    from sklearn.linear_model import LinearRegression
    from sklearn.model_selection import GroupKFold

    x = np.asarray(x, np.float64)
    x = x[:, None] if x.ndim == 1 else x
    groups = np.asarray(groups)
    tables: dict[str, pd.DataFrame] = {}
    values: dict[str, np.ndarray] = {}
    shared: dict[bytes, list[str]] = {}  # the targets of each set of finite rows
    for name, (y, circular) in targets.items():
        y = np.asarray(y, np.float64)
        if not len(x) == len(y) == len(groups):
            raise ValueError(f"x, y and groups differ in length: {len(x)}, {len(y)}, {len(groups)}")
        target = np.column_stack([np.cos(y), np.sin(y)]) if circular else y[:, None]
        keep = np.all(np.isfinite(x), axis=1) & np.all(np.isfinite(target), axis=1)
        n_groups = len(np.unique(groups[keep]))
        n_folds = min(folds, n_groups)
        if n_groups < 2:
            tables[name] = _undecodable(int(keep.sum()), n_folds,
                                        f"fewer than 2 groups (episodes) with finite rows ({n_groups})")
        elif not np.any(np.ptp(target[keep], axis=0) > 0):
            tables[name] = _undecodable(int(keep.sum()), n_folds, "constant target")
        else:
            values[name] = target
            shared.setdefault(keep.tobytes(), []).append(name)
    for key, names in shared.items():
        keep = np.frombuffer(key, dtype=bool)
        xs, gs = x[keep], groups[keep]
        n_folds = min(folds, len(np.unique(gs)))
        columns = np.cumsum([0, *(values[n].shape[1] for n in names)])
        both = np.hstack([values[n][keep] for n in names])
        rows: dict[str, list[dict]] = {n: [] for n in names}
        for train, test in GroupKFold(n_splits=n_folds).split(xs, both, gs):
            fitted = LinearRegression().fit(xs[train], both[train]).predict(xs[test]).reshape(-1, both.shape[1])
            for name, lo, hi in zip(names, columns[:-1], columns[1:], strict=True):
                target = both[:, lo:hi]
                err = ((fitted[:, lo:hi] - target[test]) ** 2).sum(axis=1)
                base = ((target[train].mean(axis=0) - target[test]) ** 2).sum(axis=1)
                for g in np.unique(gs[test]):
                    mine = gs[test] == g
                    sse, sse0 = err[mine].sum(), base[mine].sum()
                    rows[name].append({"episode": g, "n": int(mine.sum()), "sse": sse, "sse_mean": sse0,
                                       "skill": 1.0 - sse / sse0 if sse0 > 0 else np.nan, "folds": n_folds,
                                       "reason": "" if sse0 > 0 else "the training mean predicts it exactly"})
        for name in names:
            tables[name] = pd.DataFrame(rows[name], columns=SKILL_COLUMNS).sort_values("episode", kind="stable",
                                                                                       ignore_index=True)
    return {name: tables[name] for name in targets}


def _undecodable(n: int, folds: int, reason: str) -> pd.DataFrame:
    """The one row of a target that cannot be decoded: its finite rows, the folds it would have had, why."""
    return pd.DataFrame([{"episode": np.nan, "n": n, "folds": folds, "reason": reason}], columns=SKILL_COLUMNS)


def decoded_value(steps: pd.DataFrame, target: str) -> np.ndarray:
    """The values of ``target`` a readout decodes: the steps column, as log10 for the :data:`LOG_DISTANCES` (NaN
    where the distance is not positive)."""
    y = steps[target].to_numpy(np.float64)
    if target not in LOG_DISTANCES:
        return y
    with np.errstate(divide="ignore", invalid="ignore"):
        return np.where(y > 0, np.log10(np.where(y > 0, y, 1.0)), np.nan)


def decode_episodes(hidden: pd.DataFrame, steps: pd.DataFrame, targets: dict[str, bool] | None = None,
                    folds: int = DEFAULTS.decode_folds, agent: int | None = None) -> pd.DataFrame:
    """:func:`heldout_skill` of every target column of ``steps`` from the hidden state, per condition and episode
    (the dynamics table ``decoding_episodes``; Fig 6D,E, claims C18 and C19).

    All agents of a condition are pooled (only ``agent``'s rows when given:
    the homer of the homing assay) and an episode's rows, of every agent, are
    held out together. ``targets`` maps a steps column to whether it is
    circular (default :data:`DECODE_TARGETS`); a distance of
    :data:`LOG_DISTANCES` is decoded as its log10 (:func:`decoded_value`),
    under its column's name. One row per condition, target and episode
    (columns :data:`DECODED_COLUMNS`; ``readout`` True for the targets of
    :data:`READOUT_TARGETS`); a target the steps table lacks, or one that
    cannot be decoded, is one row per condition with episode NaN and the reason.
    """
    targets = DECODE_TARGETS if targets is None else targets
    hidden = hidden if agent is None else hidden[hidden["agent"] == agent]
    present = [c for c in targets if c in steps.columns]
    joined = _with_steps(hidden, steps, present)
    h, parts = units(hidden), []
    for cond, sub in joined.groupby("condition", sort=True):
        x, episodes = sub[h].to_numpy(np.float64), sub["episode"].to_numpy()
        skills = heldout_skills(x, {t: (decoded_value(sub, t), c) for t, c in targets.items() if t in present},
                                episodes, folds)
        for target, circular in targets.items():
            found = skills[target] if target in present else nan_frame(f"steps table lacks column {target!r}",
                                                                       episode=np.nan)
            parts.append(found.assign(condition=cond, target=target, circular=circular,
                                      readout=target in READOUT_TARGETS))
    if not parts:
        return nan_frame("no hidden row matches a step").reindex(columns=DECODED_COLUMNS)
    return pd.concat(parts, ignore_index=True).reindex(columns=DECODED_COLUMNS)


def summarise(episodes: pd.DataFrame, by: tuple[str, ...] = ()) -> pd.DataFrame:
    """Per condition and target (and the ``by`` columns) of a per-episode decoding table (the dynamics table
    ``decoding``; columns ``by`` then :data:`SUMMARY_COLUMNS`).

    ``skill`` is the held-out skill over all the held-out episodes, 1 - sum
    sse / sum sse_mean: the mean of the episodes' skills weighted by their
    ``sse_mean``. Unweighted, an episode whose target sits at the training mean
    all along (sse_mean near 0: an agent that never discharges) has a skill
    far below -1 (-5,000 at the smoke scale) and would swamp the mean. ``episode_skill_median`` is the median
    of the episodes' skills (what the claims' paired tests compare),
    ``n_episodes`` the episodes with a skill, ``n`` the rows decoded,
    ``folds`` and the first reason given.
    """
    keys = [*by, "condition", "target", "circular", "readout"]
    rows = []
    for values, sub in episodes.groupby(keys, sort=False, dropna=False):
        scored = sub[np.isfinite(sub["skill"].to_numpy(np.float64))]
        sse, sse_mean = scored["sse"].to_numpy(np.float64).sum(), scored["sse_mean"].to_numpy(np.float64).sum()
        reasons = [r for r in sub["reason"] if isinstance(r, str) and r]
        rows.append({**dict(zip(keys, values, strict=True)), "skill": 1.0 - sse / sse_mean if len(scored) else np.nan,
                     "episode_skill_median": scored["skill"].median() if len(scored) else np.nan,
                     "n_episodes": len(scored), "n": int(np.nansum(sub["n"].to_numpy(np.float64))),
                     "folds": sub["folds"].max(), "reason": reasons[0] if reasons else ""})
    return pd.DataFrame(rows, columns=[*by, *SUMMARY_COLUMNS])


def food_decode_episodes(hidden: pd.DataFrame, steps: pd.DataFrame, near_cm: float = DEFAULTS.claims_food_near_cm,
                         folds: int = DEFAULTS.decode_folds, agent: int | None = None) -> pd.DataFrame:
    """:func:`decode_episodes` of the food variables (:data:`FOOD_TARGETS`) on the steps with the nearest food within
    ``near_cm`` (``food`` = "near": in receptor range) and on those beyond it ("far"), per condition and episode
    (the dynamics table ``food_decoding_episodes``; Fig 6F, claim C19).

    ``near_cm``: ``analysis.claims_food_near_cm`` (the analysis passes the
    configured value; the default is its default, the authors' 5 cm
    Mormyromast food range). Steps without food (NaN distance) are in neither;
    ``agent`` as in :func:`decode_episodes`.
    Columns ``food`` then :data:`DECODED_COLUMNS`; a range with fewer than 2
    episodes is one NaN row with the reason.
    """
    columns = ["food", *DECODED_COLUMNS]
    if "dist_food_cm" not in steps.columns:
        return nan_frame("steps table lacks column 'dist_food_cm'").reindex(columns=columns)
    dist = steps["dist_food_cm"]
    parts = [decode_episodes(hidden, steps[in_range], FOOD_TARGETS, folds, agent).assign(food=food)
             for food, in_range in (("near", dist <= near_cm), ("far", dist > near_cm))]
    return pd.concat(parts, ignore_index=True)[columns]
