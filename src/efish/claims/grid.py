"""Many runs' claims at once (``efish compare-claims`` with two or more runs, e.g. the points of a sweep): one table of
claims x runs, which `efish.figures.claims_grid` draws as a heatmap.

The table keeps, per run, ``<run> recipe`` and ``<run> recipe effect`` (where its claims table has the recipe's
verdict: its top seeds together, :mod:`efish.claims.recipe`), then ``<run> verdict`` and ``<run> effect`` (its
selected seed's). The heatmap shows each run's headline (:func:`headline`): the recipe's verdict where it decided the
claim, else the selected seed's.
"""

from __future__ import annotations

from collections.abc import Mapping
from pathlib import Path

import numpy as np
import pandas as pd

from ..io import TABLE_SUFFIXES, write_table_file
from .report import has_recipe

__all__ = ["TABLE_SUFFIXES", "claims_grid", "headline", "write_table"]


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


#: A run's recipe verdict that says nothing of the claim: the recipe did not decide it (one top seed, or the claim's
#: assays not rerun), so the run's headline is its selected seed's verdict.
NO_RECIPE = ("-", "not run")


def headline(grid: pd.DataFrame, runs: list[str]) -> tuple[pd.DataFrame, pd.DataFrame, pd.DataFrame]:
    """Each run's headline verdict and effect per claim (claims x runs), and whether it is the recipe's: the
    recipe's verdict where the run has one that decided the claim, else its selected seed's; the effect of the
    verdict shown (the recipe's where it has a number, else the selected seed's), none where the verdict shown is
    "not run"."""
    index = grid["claim"]
    verdicts, effects, recipe = {}, {}, {}
    for run in runs:
        own, own_effect = grid[f"{run} verdict"], grid[f"{run} effect"].astype(float)
        if f"{run} recipe" in grid.columns:
            decided = ~grid[f"{run} recipe"].isin(NO_RECIPE)
            verdict = grid[f"{run} recipe"].where(decided, own)
            effect = grid.get(f"{run} recipe effect", own_effect).astype(float).fillna(own_effect)
            effect = effect.where(decided, own_effect)
        else:
            decided, verdict, effect = pd.Series(False, index=grid.index), own, own_effect
        verdicts[run] = verdict.to_numpy()
        effects[run] = effect.where(verdict != "not run").to_numpy(dtype=float)
        recipe[run] = decided.to_numpy()
    return (pd.DataFrame(verdicts, index=index), pd.DataFrame(effects, index=index),
            pd.DataFrame(recipe, index=index))


def write_table(grid: pd.DataFrame, path: Path) -> None:
    """``grid`` as Parquet or CSV (by ``path``'s suffix), written atomically; another suffix is a ValueError."""
    write_table_file(grid, path)
