"""Many runs' claims at once (``efish compare-claims`` with two or more runs, e.g. the points of a sweep): one table of
claims x runs, which `efish.figures.claims_grid` draws as a heatmap.

The table keeps, per run, ``<run> recipe`` and ``<run> recipe effect`` (where its claims table has the recipe's
verdict: its top seeds together, :mod:`efish.claims.recipe`), then ``<run> verdict`` and ``<run> effect`` (its
selected seed's). The heatmap shows each run's headline (:func:`headline`): the recipe's verdict where it has one.
"""

from __future__ import annotations

from collections.abc import Mapping
from pathlib import Path

import numpy as np
import pandas as pd

from ..io import atomic_path
from .report import has_recipe

#: What ``--out`` writes, by the file's suffix.
TABLE_SUFFIXES = (".parquet", ".csv")


def claim_order(claims: pd.Series) -> pd.Series:
    """A sort key of claim names by number (C2 before C10)."""
    return claims.str.extract(r"(\d+)$")[0].astype(float)


def claims_grid(tables: Mapping[str, pd.DataFrame]) -> pd.DataFrame:
    """One row per claim any table lists (by claim number), ``claim`` and ``panel`` then each run's columns in
    order: its recipe verdict and effect where it has them, its selected seed's verdict and effect. A claim a run
    lacks is '-' (its effect NaN)."""
    runs = []
    for run, table in tables.items():
        columns = {"verdict": f"{run} verdict", "effect": f"{run} effect"}
        if has_recipe(table):
            recipe = {"recipe_verdict": f"{run} recipe", "recipe_effect": f"{run} recipe effect"}
            columns = {k: v for k, v in recipe.items() if k in table.columns} | columns
        runs.append(table.set_index("claim")[list(columns)].rename(columns=columns))
    panels = pd.concat([t.set_index("claim")["panel"] for t in tables.values()])
    grid = pd.concat(runs, axis=1)
    grid.insert(0, "panel", panels[~panels.index.duplicated()].reindex(grid.index))
    grid = grid.reset_index().rename(columns={"index": "claim"})
    grid = grid.iloc[np.lexsort((grid["claim"], claim_order(grid["claim"])))].reset_index(drop=True)
    verdicts = [c for c in grid.columns if c.endswith((" recipe", " verdict"))]
    grid[verdicts] = grid[verdicts].fillna("-")
    return grid


def headline(grid: pd.DataFrame, runs: list[str]) -> tuple[pd.DataFrame, pd.DataFrame]:
    """Each run's headline verdict and effect per claim (claims x runs): the recipe's verdict where the run has it,
    else its selected seed's; the recipe's effect where it has a number, else the selected seed's."""
    def verdict(run: str) -> pd.Series:
        return grid.get(f"{run} recipe", grid[f"{run} verdict"])

    def effect(run: str) -> pd.Series:
        own = grid[f"{run} effect"]
        return grid[f"{run} recipe effect"].fillna(own) if f"{run} recipe effect" in grid.columns else own

    index = grid["claim"]
    verdicts = pd.DataFrame({run: verdict(run).to_numpy() for run in runs}, index=index)
    effects = pd.DataFrame({run: effect(run).to_numpy(dtype=float) for run in runs}, index=index)
    return verdicts, effects


def write_table(grid: pd.DataFrame, path: Path) -> None:
    """``grid`` as Parquet or CSV (by ``path``'s suffix), written atomically; another suffix is a ValueError."""
    if path.suffix not in TABLE_SUFFIXES:
        raise ValueError(f"--out {path}: the table is written as {' or '.join(TABLE_SUFFIXES)}")
    path.parent.mkdir(parents=True, exist_ok=True)
    with atomic_path(path) as tmp:
        if path.suffix == ".parquet":
            grid.to_parquet(tmp, index=False)
        else:
            grid.to_csv(tmp, index=False)
