"""Rollout tables: schema, keys and consistency between tables."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

from efish.config import compose
from efish.rollout.run import run_episodes
from efish.rollout.schema import SCHEMAS, check_file, to_table
from efish.rollout.tables import write_tables


class GreedyForward:
    """A scripted policy: full speed ahead, no turn, always emit, never bite."""

    def initial_hidden(self, b, n=1):
        return np.zeros((b, n, 1), np.float32)

    def act(self, obs, hidden, starts, deterministic=True):
        a = np.zeros(obs.shape[:2] + (4,))
        a[..., 0], a[..., 2] = 40.0, 1.0
        return a, hidden


@pytest.fixture(scope="module")
def tables():
    cfg = compose(["arena=collective", "env.episode_steps=30"])
    return run_episodes(cfg, GreedyForward(), episodes=3, condition="control", seed=4)


def test_tables_match_their_schemas_when_written(tables, tmp_path):
    paths = write_tables(tables, tmp_path)
    for path in paths:
        check_file(path, path.stem)
        assert pd.read_parquet(path).shape[0] == len(tables[path.stem])


def test_steps_are_one_row_per_episode_step_agent(tables):
    s = tables["steps"]
    assert len(s) == 3 * 30 * 4 and not s.duplicated(["condition", "episode", "t", "agent"]).any()
    np.testing.assert_allclose(s["t_ms"], s["t"] * 1000 / 83)
    assert s["eod"].all() and not s["bite"].any()
    assert (s["dist_wall_cm"] >= 1 - 1e-9).all() and (s["dist_agent_cm"] >= 2 - 1e-9).all()


def test_episode_and_food_tables_agree_with_the_steps(tables):
    s, e, f = tables["steps"], tables["episodes"], tables["food"]
    eaten_steps = s.groupby("episode")["ate"].sum()
    eaten_food = (f["t_eaten"] >= 0).groupby(f["episode"]).sum().reindex(eaten_steps.index, fill_value=0)
    np.testing.assert_array_equal(eaten_steps.to_numpy(), eaten_food.to_numpy())
    assert (e.groupby("episode")["food_eaten"].sum() == eaten_steps).all()
    assert (e["eod_probability"] == 1.0).all() and (e["steps"] == 30).all()


def test_a_missing_column_is_one_clear_error(tables):
    with pytest.raises(ValueError, match="missing columns \\['reward'\\]"):
        to_table(tables["steps"].drop(columns="reward"), "steps")


def test_every_schema_column_is_snake_case():
    for schema in SCHEMAS.values():
        for name in schema.names:
            assert name == name.lower() and " " not in name
