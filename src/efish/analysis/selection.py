"""Seed selection by an ethological criterion (docs/methods/training.md#seed-selection).

Per seed, from its evaluation episodes: mean total food per episode, and the
median over episodes of slope, intercept and R^2 of the OLS fit
food_eaten ~ size over the episode's agents. Seeds with a non-positive median
intercept are dropped; food, slope and R^2 are ranked descending; the smallest
rank sum wins, ties going to more food.
"""

from __future__ import annotations

import re
from collections.abc import Iterable
from pathlib import Path

import numpy as np
import pandas as pd

from ..io import read_parquet


def ols_fit(x: np.ndarray, y: np.ndarray) -> tuple[float, float, float]:
    """(slope, intercept, R^2) of y ~ x; R^2 is 0 when y does not vary, NaN slope when x does not."""
    x, y = np.asarray(x, dtype=np.float64), np.asarray(y, dtype=np.float64)
    vx = np.var(x)
    if vx == 0:
        return np.nan, float(np.mean(y)), np.nan
    slope = float(np.mean((x - x.mean()) * (y - y.mean())) / vx)
    intercept = float(y.mean() - slope * x.mean())
    ss_tot = float(np.sum((y - y.mean()) ** 2))
    r2 = 0.0 if ss_tot == 0 else 1.0 - float(np.sum((y - intercept - slope * x) ** 2)) / ss_tot
    return slope, intercept, r2


def seed_statistics(episodes: pd.DataFrame) -> pd.DataFrame:
    """One row per seed from an episodes table with a ``seed`` column (the statistics of
    docs/methods/training.md#seed-selection)."""
    required = {"seed", "episode", "size", "food_eaten"}
    if missing := required - set(episodes.columns):
        raise ValueError(f"episodes table lacks columns {sorted(missing)}")
    rows = []
    for seed, s in episodes.groupby("seed", sort=True):
        fits = np.array([ols_fit(e["size"], e["food_eaten"]) for _, e in s.groupby("episode")])
        rows.append({"seed": seed, "food_per_episode": s.groupby("episode")["food_eaten"].sum().mean(),
                     "slope": np.nanmedian(fits[:, 0]), "intercept": np.nanmedian(fits[:, 1]),
                     "r2": np.nanmedian(fits[:, 2]), "episodes": s["episode"].nunique()})
    return pd.DataFrame(rows)


RANKING_COLUMNS = ("seed", "food_per_episode", "slope", "intercept", "r2", "episodes", "eligible", "fallback",
                   "rank_food_per_episode", "rank_slope", "rank_r2", "rank_sum", "selected")


def rank_seeds(stats: pd.DataFrame) -> pd.DataFrame:
    """The full ranking table: eligible seeds ranked, the winner first, dropped seeds last.

    When no seed is eligible (e.g. untrained seeds that eat nothing, at smoke
    scale), all are ranked and the winner is marked in a ``fallback`` column.
    """
    table = stats.copy()
    table["eligible"] = table["intercept"] > 0
    table["fallback"] = not table["eligible"].any()
    ok = table["eligible"] | table["fallback"]
    for col in ("food_per_episode", "slope", "r2"):
        table[f"rank_{col}"] = np.nan
        table.loc[ok, f"rank_{col}"] = table.loc[ok, col].rank(ascending=False, method="average")
    table["rank_sum"] = table[["rank_food_per_episode", "rank_slope", "rank_r2"]].sum(axis=1, min_count=3)
    table = table.sort_values(["eligible", "rank_sum", "food_per_episode"], ascending=[False, True, False],
                              na_position="last").reset_index(drop=True)
    table["selected"] = False
    table.loc[0, "selected"] = True
    return table[list(RANKING_COLUMNS)]


def read_seed_episodes(paths: Iterable[str | Path]) -> pd.DataFrame:
    """The episodes tables of several seeds as one frame with a ``seed`` column.

    Each path must lie under a folder named ``seed_<n>`` (how the pipeline
    writes them); a path without one, or a file that is not Parquet, is one
    clear ``ValueError``.
    """
    frames = []
    for path in paths:
        m = re.search(r"seed_(\d+)", str(path))
        if not m:
            raise ValueError(f"cannot tell the seed of {path}: put it under a folder named seed_<n>")
        frames.append(read_parquet(path, "an episodes table").assign(seed=int(m.group(1))))
    if not frames:
        raise ValueError("no episodes tables given")
    return pd.concat(frames, ignore_index=True)


def select_seed(paths: Iterable[str | Path]) -> tuple[pd.DataFrame, int]:
    """Seed selection (docs/methods/training.md#seed-selection) on the episodes tables at ``paths``: the full ranking
    table and the chosen seed."""
    table = rank_seeds(seed_statistics(read_seed_episodes(paths)))
    return table, int(table.loc[table["selected"], "seed"].iloc[0])


def stack_top_seeds(paths: Iterable[str | Path], ranking: pd.DataFrame) -> pd.DataFrame:
    """The tables at ``paths`` (each under a ``seed_<n>`` folder) as one frame with ``seed`` and ``rank``
    columns, ``rank`` 1 for the best-ranked seed of ``ranking``: the supplement's top-seed panels read it.

    A seed absent from the ranking is one clear ``ValueError``.
    """
    table = read_seed_episodes(paths)
    rank = {int(seed): i for i, seed in enumerate(ranking["seed"], 1)}
    if unknown := sorted(set(table["seed"]) - set(rank)):
        raise ValueError(f"seeds {unknown} are not in the ranking table")
    return table.assign(rank=table["seed"].map(rank)).sort_values(["rank", "episode", "agent"], ignore_index=True)
