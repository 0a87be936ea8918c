"""Decoding world variables from hidden states, scored per held-out episode (the claims' C18 and C19).

:func:`heldout_skill` fits one linear readout per fold of episodes and scores
it on each held-out episode separately, so that two targets (or two subsets of
steps) can be compared paired over episodes; :func:`efish.analysis.dynamics.decode`
scores the same kind of readout pooled over a condition's episodes (Fig 6D-F).
"""

from __future__ import annotations

import numpy as np
import pandas as pd


def heldout_skill(x: np.ndarray, targets: dict[str, tuple[np.ndarray, bool]], groups: np.ndarray,
                  folds: int) -> pd.DataFrame:
    """Held-out decoding skill of each target per group (episode): 1 - MSE(readout) / MSE(train mean).

    The readout is OLS from ``x`` (sklearn LinearRegression, all targets fitted
    jointly) under GroupKFold(``folds``) over ``groups``, like
    :func:`efish.analysis.dynamics.decode`; the skill is scored per held-out
    group instead of pooled, so two targets (or two subsets) can be compared
    paired over episodes. A circular target (radians) is (cos, sin), MSE summed.
    Rows with a non-finite value are dropped. Columns: group, target, n, skill.
    """
    from sklearn.linear_model import LinearRegression
    from sklearn.model_selection import GroupKFold

    x = np.asarray(x, np.float64)
    blocks, names = [], []
    for name, (y, circular) in targets.items():
        y = np.asarray(y, np.float64)
        blocks.append(np.column_stack([np.cos(y), np.sin(y)]) if circular else y[:, None])
        names += [name] * blocks[-1].shape[1]
    y, names = np.hstack(blocks), np.asarray(names)
    keep = np.all(np.isfinite(x), axis=1) & np.all(np.isfinite(y), axis=1)
    x, y, groups = x[keep], y[keep], np.asarray(groups)[keep]
    n_groups = len(np.unique(groups))
    if n_groups < 2:
        raise ValueError(f"fewer than 2 episodes with finite rows to decode ({n_groups})")
    rows = []
    for train, test in GroupKFold(n_splits=min(folds, n_groups)).split(x, y, groups):
        pred = LinearRegression().fit(x[train], y[train]).predict(x[test])
        err, base = (pred - y[test]) ** 2, (y[train].mean(axis=0) - y[test]) ** 2
        for g in np.unique(groups[test]):
            mine = groups[test] == g
            for name in targets:
                cols = names == name
                mse, mse0 = err[mine][:, cols].sum(axis=1).mean(), base[mine][:, cols].sum(axis=1).mean()
                rows.append({"group": g, "target": name, "n": int(mine.sum()),
                             "skill": 1 - mse / mse0 if mse0 > 0 else np.nan})
    return pd.DataFrame(rows, columns=["group", "target", "n", "skill"])
