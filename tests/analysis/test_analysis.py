"""Analyses with known answers on synthetic tables."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

from efish.analysis.inequality import theil_t, win_ratio
from efish.analysis.selection import ols_fit, rank_seeds, seed_statistics


def test_theil_known_values():
    assert theil_t(np.ones(5)) == 0.0
    assert theil_t(np.array([0, 0, 0, 7.0])) == pytest.approx(np.log(4))  # one has everything: ln N
    x = np.array([1.0, 2.0, 3.0])
    expected = np.mean((x / 2) * np.log(x / 2))
    assert theil_t(x) == pytest.approx(expected)
    assert theil_t(10 * x) == pytest.approx(theil_t(x))  # scale invariant
    assert theil_t(np.zeros(3)) == 0.0
    with pytest.raises(ValueError):
        theil_t(np.array([-1.0, 2.0]))


def test_win_ratio():
    np.testing.assert_allclose(win_ratio([3, 0, 0], [1, 2, 0]), [0.75, 0.0, np.nan])


def test_ols_recovers_a_line():
    x = np.array([0.1, 0.4, 0.7, 0.9])
    slope, intercept, r2 = ols_fit(x, 2.0 + 5.0 * x)
    assert (slope, intercept, r2) == pytest.approx((5.0, 2.0, 1.0))


def synthetic_episodes(rng, seeds: dict[int, tuple[float, float, float]], episodes=20) -> pd.DataFrame:
    """seed -> (intercept, slope, noise sd) of food ~ size, 4 agents per episode."""
    rows = []
    for seed, (a, b, sd) in seeds.items():
        for e in range(episodes):
            size = rng.uniform(0, 1, 4)
            food = a + b * size + rng.normal(0, sd, 4)
            rows += [{"seed": seed, "episode": e, "agent": i, "size": size[i], "food_eaten": food[i]} for i in range(4)]
    return pd.DataFrame(rows)


def test_selection_prefers_more_food_steeper_and_cleaner_size_effects():
    rng = np.random.default_rng(0)
    df = synthetic_episodes(rng, {1: (2.0, 8.0, 0.1),    # best on every criterion
                                  2: (2.0, 4.0, 0.1),
                                  3: (1.0, 2.0, 2.0),
                                  4: (-3.0, 20.0, 0.1)})  # steepest and richest, but negative intercept: dropped
    stats = seed_statistics(df)
    assert stats.set_index("seed").loc[4, "intercept"] < 0
    table = rank_seeds(stats)
    assert table.loc[0, "seed"] == 1 and table.loc[0, "selected"] and table["selected"].sum() == 1
    assert list(table["seed"]) == [1, 2, 3, 4] and not table.loc[3, "eligible"]
    assert table.loc[0, "rank_sum"] == 3.0


def test_selection_ties_go_to_more_food():
    stats = pd.DataFrame({"seed": [1, 2], "food_per_episode": [10.0, 12.0], "slope": [3.0, 2.0],
                          "intercept": [1.0, 1.0], "r2": [0.5, 0.5], "episodes": [5, 5]})
    table = rank_seeds(stats)
    assert table.loc[0, "rank_sum"] == table.loc[1, "rank_sum"] and table.loc[0, "seed"] == 2


def test_missing_columns_are_named():
    with pytest.raises(ValueError, match="food_eaten"):
        seed_statistics(pd.DataFrame({"seed": [1], "episode": [0], "size": [0.5]}))


def test_without_eligible_seeds_all_are_ranked_and_flagged():
    stats = pd.DataFrame({"seed": [1, 2], "food_per_episode": [0.0, 1.0], "slope": [0.0, 0.5],
                          "intercept": [0.0, -1.0], "r2": [0.0, 0.1], "episodes": [5, 5]})
    table = rank_seeds(stats)
    assert table["fallback"].all() and table.loc[0, "seed"] == 2 and table["selected"].sum() == 1
