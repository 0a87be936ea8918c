"""A results folder of synthetic tables shaped like a real run's: every assay of the laptop scale gets
rollout tables from ``tests.helpers.rollout_tables`` with its own conditions and agent count, and the
``conditions.parquet`` efish assay records (:func:`conditions_of`), and every analysis of it runs for real on
them (``efish.analysis.registry.run``) and records its settings as efish analyze does, so panels are drawn from
the same table shapes the pipeline writes."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd
import pytest
from tests.helpers import cfg_with, conditions_of, rollout_tables

from efish.analysis.registry import analyses_for, run, tables_written
from efish.analysis.selection import rank_seeds, seed_statistics, stack_top_seeds
from efish.config import compose
from efish.config.recorded import settings_table
from efish.figures.panel import conditions_key, settings_key
from efish.layout import ANALYSIS_SETTINGS
from efish.rollout.tables import write_tables

SEEDS = 2


def _write(tables: dict[str, pd.DataFrame], folder: Path) -> None:
    folder.mkdir(parents=True, exist_ok=True)
    for name, table in tables.items():
        if name == "conditions":  # as efish assay writes it, with its declared schema
            write_tables({name: table}, folder)
        else:
            table.to_parquet(folder / f"{name}.parquet", index=False)


def _assay_tables(name: str, seed: int) -> tuple[dict, object]:
    cfg = compose(["scale=smoke", f"assay={name}"])
    conditions = tuple(cfg.assay.conditions) or ("control",)
    tables = rollout_tables(seed=seed, conditions=conditions, episodes=3, n_agents=max(cfg.env.n_agents, 2),
                            steps=120, error_angles=cfg.env.task == "homing", arena_cm=cfg.arena.width_cm)
    tables["conditions"] = conditions_of(name)
    return {t: tables[t] for t in tables_written(cfg.assay)}, cfg


@pytest.fixture(scope="session")
def recorded():
    """``recorded("onepatch", "bot")``: the conditions tables a panel's draw function reads beside its inputs,
    keyed like :attr:`efish.figures.panel.Panel.conditions`; ``overrides=[...]`` records them under run
    overrides."""
    def tables(*assays: str, overrides=()) -> dict[str, pd.DataFrame]:
        return {conditions_key(a): conditions_of(a, *overrides) for a in assays}

    return tables


@pytest.fixture(scope="session")
def analysed():
    """``analysed("dynamics", "wide2", overrides=[...])``: the settings table an analysis job records, keyed like
    :attr:`efish.figures.panel.Panel.settings`, for the analysis settings under ``overrides``."""
    def tables(analysis: str, *assays: str, overrides=()) -> dict[str, pd.DataFrame]:
        return {settings_key(analysis, a): settings_table(cfg_with(*overrides).analysis) for a in assays}

    return tables


@pytest.fixture(scope="session")
def synthetic_results(tmp_path_factory) -> Path:
    """``results/{run}``-shaped folder: assays/<assay>/*.parquet, analysis/<analysis>/<assay>/*.parquet,
    train/seed_<n>/metrics.parquet, analysis/selection/ranking.parquet and the top seeds' assays."""
    root = tmp_path_factory.mktemp("results")
    base = compose(["scale=laptop"])
    for i, assay in enumerate(base.scale.assays):
        tables, cfg = _assay_tables(assay, seed=i)
        _write(tables, root / "assays" / assay)
        for analysis in analyses_for(assay, tables):
            _write({**run(analysis.name, tables, cfg.analysis), ANALYSIS_SETTINGS: settings_table(cfg.analysis)},
                   root / "analysis" / analysis.name / assay)
    episodes = []
    for seed in range(1, SEEDS + 1):
        rng = np.random.default_rng(seed)
        steps = np.arange(1, 11) * 1000
        _write({"metrics": pd.DataFrame({
            "env_steps": steps, "episode_return": np.cumsum(rng.normal(0.5, 0.2, 10)),
            "food_reward": np.cumsum(rng.normal(0.4, 0.1, 10)), "bitten_reward": -rng.uniform(0, 0.1, 10),
            "policy_loss": rng.normal(0, 0.01, 10), "value_loss": np.exp(-steps / 5000),
            "entropy": 2 - steps / 10000})}, root / "train" / f"seed_{seed}")
        sel, _ = _assay_tables("selection", seed)
        episodes.append(sel["episodes"].assign(seed=seed))
    ranking = rank_seeds(seed_statistics(pd.concat(episodes, ignore_index=True)))
    _write({"ranking": ranking}, root / "analysis" / "selection")
    for assay in base.scale.top_seed_assays:
        paths = []
        for seed in range(1, SEEDS + 1):
            _write({"episodes": _assay_tables(assay, seed)[0]["episodes"]}, root / f"seeds/seed_{seed}/assays/{assay}")
            paths.append(root / f"seeds/seed_{seed}/assays/{assay}/episodes.parquet")
        _write({"episodes": stack_top_seeds(paths, ranking)}, root / "seeds" / assay)
    return root
