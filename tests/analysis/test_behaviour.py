"""Behaviour analyses with known answers on scripted episode and step tables."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

from efish.analysis.behaviour import (
    bite_matrix,
    bot_reach_rates,
    eod_probability,
    episode_summary,
    food_per_agent_episode,
    food_time_course,
    food_vs_size,
    food_vs_size_per_episode,
    nearest_neighbour,
    reach_rates,
    reach_times,
    theil_per_episode,
    win_ratios,
)


def episodes_table(food, sizes=(0.1, 0.4, 0.6, 0.9), condition="c") -> pd.DataFrame:
    """One row per agent-episode; ``food`` is a list of per-episode food lists."""
    rows = [{"condition": condition, "episode": e, "agent": a, "size": sizes[a], "food_eaten": f,
             "eod_probability": 0.25 * a, "bites_given": a, "bites_received": 3 - a, "mean_nn_dist_cm": 10.0 + a}
            for e, fs in enumerate(food) for a, f in enumerate(fs)]
    return pd.DataFrame(rows)


def steps_table(n_agents=2, t=10, **columns) -> pd.DataFrame:
    base = {"condition": "c", "episode": 0, "t": np.tile(np.arange(t), n_agents),
            "agent": np.repeat(np.arange(n_agents), t), "size": np.repeat(np.linspace(0.2, 0.8, n_agents), t),
            "eod": False, "ate": False, "bite_target": -1, "dist_agent_cm": 20.0, "x_cm": 0.0, "y_cm": 0.0}
    return pd.DataFrame({**base, **columns})


def test_food_per_agent_episode_shares_and_ranks():
    out = food_per_agent_episode(episodes_table([[1, 1, 2, 4], [0, 0, 0, 0]]))
    assert out["food_share"].iloc[:4].tolist() == [0.125, 0.125, 0.25, 0.5]
    assert out["food_share"].iloc[4:].isna().all() and (out["reason"].iloc[4:] == "no food eaten in the episode").all()
    assert out["size_rank"].tolist() == [0, 1, 2, 3] * 2


def test_food_vs_size_recovers_a_line():
    rng = np.random.default_rng(0)
    sizes = rng.uniform(0, 1, (20, 4))
    eps = pd.concat([episodes_table([2 + 8 * s + rng.normal(0, 0.1, 4)], sizes=s).assign(episode=e)
                     for e, s in enumerate(sizes)])
    out = food_vs_size(eps)
    assert out.loc[0, "effect"] == pytest.approx(8.0, abs=0.2) and out.loc[0, "intercept"] == pytest.approx(2, abs=0.2)
    assert out.loc[0, "n"] == 80 and out.loc[0, "p"] < 1e-4 and out.loc[0, "stars"] == "****"
    per = food_vs_size_per_episode(eps)
    assert len(per) == 20 and per["slope"].median() == pytest.approx(8.0, abs=0.5)


def test_food_vs_size_degenerate():
    out = food_vs_size(episodes_table([[1, 2, 3, 4]], sizes=(0.5,) * 4))
    assert np.isnan(out.loc[0, "effect"]) and out.loc[0, "reason"] == "size is constant"
    assert food_vs_size(episodes_table([[3, 3, 3, 3]])).loc[0, "reason"] == "food is constant"
    assert food_vs_size_per_episode(episodes_table([[1, 2, 3, 4]], sizes=(0.5,) * 4)).loc[0, "reason"] != ""


def test_theil_per_episode_known_values():
    out = theil_per_episode(episodes_table([[2, 2, 2, 2], [0, 0, 0, 9], [0, 0, 0, 0], [1, -1, 0, 0]]))
    assert out["theil_t"].iloc[:3].tolist() == pytest.approx([0.0, np.log(4), 0.0])
    assert np.isnan(out.loc[3, "theil_t"]) and "negative" in out.loc[3, "reason"]
    assert (out["n_agents"] == 4).all() and out.loc[1, "total"] == 9


def test_win_ratios():
    eps = episodes_table([[0, 0, 0, 0]]).assign(bites_given=[3, 0, 0, 1], bites_received=[1, 2, 0, 1])
    out = win_ratios(eps)
    np.testing.assert_allclose(out["win_ratio"], [0.75, 0.0, np.nan, 0.5])
    assert out["reason"].tolist() == ["", "", "no bites given or received", ""]


def test_bite_matrix_by_size_rank():
    steps = steps_table(n_agents=4)  # sizes rise with the agent id: agent 3 is the largest
    biter3 = steps["agent"] == 3
    steps.loc[biter3 & steps["t"].isin([3, 7]), "bite_target"] = 0  # largest bites smallest twice
    steps.loc[biter3 & (steps["t"] == 1), "bite_target"] = 1         # and the second smallest once
    out = bite_matrix(steps).set_index(["biter_class", "victim_class"])
    assert out.loc[(3, 0), "bites"] == 2 and out.loc[(3, 1), "bites"] == 1 and out["bites"].sum() == 3
    assert out.loc[(3, 0), "fraction"] == pytest.approx(2 / 3) and len(out) == 16
    none = bite_matrix(steps_table(n_agents=4))
    assert none["fraction"].isna().all() and (none["reason"] == "no bites").all()
    by_bin = bite_matrix(steps, by="bin", bins=2).set_index(["biter_class", "victim_class"])
    assert by_bin.loc[(1, 0), "bites"] == 3
    with pytest.raises(ValueError, match="by must be"):
        bite_matrix(steps, by="weight")


def test_nearest_neighbour_and_eod_probability():
    steps = steps_table(eod=np.r_[np.ones(10), np.zeros(5), np.ones(5)].astype(bool),
                        dist_agent_cm=np.r_[np.full(10, 4.0), np.arange(10.0)])
    nn, eod = nearest_neighbour(steps), eod_probability(steps)
    assert nn["mean_nn_dist_cm"].tolist() == [4.0, 4.5] and nn["median_nn_dist_cm"].tolist() == [4.0, 4.5]
    assert eod["eod_probability"].tolist() == [1.0, 0.5] and eod["size"].tolist() == pytest.approx([0.2, 0.8])
    alone = nearest_neighbour(steps_table(n_agents=1, dist_agent_cm=np.nan))
    assert np.isnan(alone.loc[0, "mean_nn_dist_cm"]) and alone.loc[0, "reason"] == "no other agent"


def test_episode_summary():
    out = episode_summary(episodes_table([[2, 2, 2, 2], [0, 0, 0, 8]]))
    assert out["food_total"].tolist() == [8, 8] and out["food_per_agent"].tolist() == [2.0, 2.0]
    assert out["theil_t"].tolist() == pytest.approx([0.0, np.log(4)]) and out["bites"].tolist() == [6, 6]
    assert out["eod_probability"].tolist() == pytest.approx([0.375, 0.375])


def test_food_time_course_is_the_mean_cumulative_food():
    a = steps_table(n_agents=1, ate=np.isin(np.arange(10), [2, 5]))
    b = steps_table(n_agents=1, ate=np.isin(np.arange(10), [5]), episode=1)
    out = food_time_course(pd.concat([a, b])).set_index("t")
    assert out["mean_food"].tolist() == [0, 0, 0.5, 0.5, 0.5, 1.5, 1.5, 1.5, 1.5, 1.5]
    assert (out["n_episodes"] == 2).all()
    assert food_time_course(pd.concat([a, b]), every=5)["t"].tolist() == [0, 5]


def test_reach_times_and_rates():
    patch = (75.0, 75.0), 6.0  # the one-patch arena's: the centre of 150 x 150 cm, radius 6 cm
    x = np.r_[np.linspace(75 - 30, 75, 10), np.full(10, 10.0)]  # agent 0 walks to the patch; agent 1 stays away
    steps = steps_table(n_agents=2, x_cm=x, y_cm=75.0)
    times = reach_times(steps, *patch)
    assert times["reached"].tolist() == [True, False]
    t_in = int(np.argmax(np.abs(x[:10] - 75) <= 6.0))
    assert times.loc[0, "t_reach"] == t_in and np.isnan(times.loc[1, "t_reach"])
    rates = reach_rates(steps, *patch).set_index("agent")
    assert rates.loc[0, "reach_rate"] == 1.0 and rates.loc[1, "reach_rate"] == 0.0
    assert "no episode reached" in rates.loc[1, "reason"]
    bot = bot_reach_rates(steps, *patch, agent=0)
    assert bot["agent"].tolist() == [0] and bot.loc[0, "median_t_reach"] == t_in
    assert bot_reach_rates(steps, *patch, agent=5).loc[0, "reason"] == "no agent-episodes"


def test_the_patch_is_the_callers():
    """Reach is measured against the patch the caller names (the run's), not a built-in one."""
    steps = steps_table(n_agents=1, x_cm=np.full(10, 20.0), y_cm=20.0)
    assert reach_times(steps, (20.0, 20.0), 1.0)["reached"].tolist() == [True]
    assert reach_times(steps, (75.0, 75.0), 6.0)["reached"].tolist() == [False]
    assert reach_times(steps, (26.0, 20.0), 6.0)["reached"].tolist() == [True]  # at exactly the radius
    # each condition's own arena, as it recorded it: the patch at (20, 20) in "c", at the centre of 150 cm in "big"
    two = pd.concat([steps, steps.assign(condition="big")], ignore_index=True)
    per = reach_times(two, ({"c": 20.0, "big": 75.0}, {"c": 20.0, "big": 75.0}), {"c": 1.0, "big": 6.0})
    assert per.set_index("condition")["reached"].to_dict() == {"big": False, "c": True}


def test_missing_columns_are_named():
    with pytest.raises(ValueError, match="bites_received"):
        win_ratios(episodes_table([[1, 1, 1, 1]]).drop(columns="bites_received"))
    with pytest.raises(ValueError, match="bite_target"):
        bite_matrix(steps_table().drop(columns="bite_target"))


def test_empty_and_all_nan_tables_say_why():
    empty = episodes_table([[1, 2, 3, 4]]).iloc[:0]
    assert food_vs_size(empty).loc[0, "reason"] == "fewer than 3 agent-episodes"
    assert food_per_agent_episode(empty).empty and theil_per_episode(empty).empty  # no units, no rows
    nan = episodes_table([[np.nan] * 4]).assign(size=np.nan)
    assert (food_per_agent_episode(nan)["reason"] == "food_eaten is missing").all()
    assert food_vs_size_per_episode(nan).loc[0, "reason"] == "missing size or food_eaten"
    assert np.isnan(episode_summary(nan).loc[0, "theil_t"]) and episode_summary(nan).loc[0, "reason"] != ""
    no_size = bite_matrix(steps_table(n_agents=2, size=np.nan, bite_target=np.tile([1, -1], 10)))
    assert no_size.loc[0, "reason"] == "no agent has a known size"
    assert food_time_course(steps_table().iloc[:0]).loc[0, "reason"] == "empty steps table"
