"""The one-patch analysis's statistic tables: roles from the condition names, role_tests (Mann-Whitney of food
by role) and reach_tests (Fisher exact of the bot assay's reach counts), on data with the effect built in."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest
from scipy import stats as sps

from efish.analysis.onepatch import bot_reach_counts, food_from_steps, reach_tests, role_tests, roles
from efish.analysis.stats import STAT_COLUMNS, fisher_rates, fisher_row


def onepatch_steps(b_social: float, b_alone: float, episodes: int = 8, steps: int = 10) -> pd.DataFrame:
    """Steps whose ``ate`` sums to known food: B (agent 1) eats ``b_social`` + episode in each social condition,
    ``b_alone`` + episode alone; A eats 3 + episode everywhere."""
    rows = []
    for e in range(episodes):
        eaten = {("A_gt_B", 0): 3, ("A_gt_B", 1): b_social, ("A_lt_B", 0): 3, ("A_lt_B", 1): b_social,
                 ("A_alone", 0): 3, ("B_alone", 0): b_alone}
        for (cond, agent), k in eaten.items():
            ate = np.zeros(steps, int)
            ate[: int(k) + e % 3] = 1
            rows.append(pd.DataFrame({"condition": cond, "episode": e, "agent": agent, "t": np.arange(steps),
                                      "ate": ate}))
    return pd.concat(rows, ignore_index=True)


def test_food_is_the_sum_of_ate_per_agent_episode():
    food = food_from_steps(onepatch_steps(5, 1))
    row = food[(food["condition"] == "A_gt_B") & (food["episode"] == 2) & (food["agent"] == 1)]
    assert row["food_eaten"].item() == 5 + 2


def test_roles_follow_the_assay_config():
    food = pd.DataFrame({"condition": ["A_gt_B", "A_gt_B", "A_alone", "B_alone", "bot0.5_B0.5_rate0_frozen"],
                         "agent": [0, 1, 0, 0, 1]})
    r = roles(food)
    assert r["role"].tolist() == ["A", "B", "A", "B"]
    assert r["setting"].tolist() == ["A_gt_B", "A_gt_B", "alone", "alone"]


def test_role_tests_find_b_eating_more_with_a_and_a_unaffected():
    food = food_from_steps(onepatch_steps(b_social=6, b_alone=1))
    tests = role_tests(food)
    assert list(tests.columns[: len(STAT_COLUMNS)]) == STAT_COLUMNS
    b = tests[tests["role"] == "B"].set_index("group")
    assert set(b.index) == {"A_gt_B", "A_lt_B"} and (b["control"] == "alone").all()
    assert b.loc["A_gt_B", "effect"] == pytest.approx(5.0)  # medians 6+1 and 1+1
    social = food[(food["condition"] == "A_gt_B") & (food["agent"] == 1)]["food_eaten"]
    alone = food[food["condition"] == "B_alone"]["food_eaten"]
    assert b.loc["A_gt_B", "p"] == pytest.approx(sps.mannwhitneyu(social, alone).pvalue)
    assert b.loc["A_gt_B", "p"] < 0.01 and b.loc["A_gt_B", "stars"] != "ns"
    a = tests[tests["role"] == "A"].iloc[0]
    assert (a["group"], a["effect"], a["n"], a["n_control"]) == ("social", 0.0, 16, 8)


def test_role_tests_say_why_there_is_no_test():
    food = food_from_steps(onepatch_steps(6, 1))
    no_b_alone = role_tests(food[food["condition"] != "B_alone"])
    assert np.isnan(no_b_alone.loc[no_b_alone["role"] == "B", "p"]).all()
    assert "B_alone" in no_b_alone.loc[no_b_alone["role"] == "B", "reason"].item()
    bot = role_tests(pd.DataFrame({"condition": ["bot0.5_B0.5_rate0_frozen"], "agent": [1], "food_eaten": [1.0]}))
    assert len(bot) == 1 and "no one-patch condition" in bot["reason"].item()


def bot_reach(k: dict[tuple[str, bool], int], n: int = 10) -> pd.DataFrame:
    """A reach_rates table of the bot assay: B (agent 1) reached k[(motion, emitting)] of n episodes."""
    rows = []
    for rate in (0, 0.5, 1):
        for motion in ("frozen", "moving"):
            cond = f"bot0.5_B0.5_rate{rate:g}_{motion}"
            rows += [{"condition": cond, "agent": 1, "n_episodes": n, "n_reached": k[(motion, rate > 0)]},
                     {"condition": cond, "agent": 0, "n_episodes": n, "n_reached": n}]  # the bot: never counted
    return pd.DataFrame(rows)


def test_reach_tests_pool_the_trained_agents_episodes_and_run_fisher():
    reach = bot_reach({("frozen", True): 9, ("frozen", False): 5, ("moving", True): 4, ("moving", False): 0})
    counts = bot_reach_counts(reach, "mobility")
    assert counts.loc["frozen"].tolist() == [9 + 9 + 5, 30] and counts.loc["moving"].tolist() == [8, 30]
    tests = reach_tests(reach).set_index("contrast")
    mob = tests.loc["mobility"]
    assert (mob["group"], mob["control"], mob["n"], mob["n_control"]) == ("frozen", "moving", 30, 30)
    assert mob["effect"] == pytest.approx(23 / 30 - 8 / 30)
    assert mob["p"] == pytest.approx(sps.fisher_exact([[23, 7], [8, 22]]).pvalue)
    eod = tests.loc["eod"]  # emitting: rates 0.5 and 1, 40 episodes; silent: rate 0, 20 episodes
    assert (eod["group"], eod["n"], eod["n_control"]) == ("emitting", 40, 20)
    assert eod["effect"] == pytest.approx(26 / 40 - 5 / 20)


def test_reach_tests_without_bot_conditions_are_nan_rows_with_a_reason():
    reach = pd.DataFrame({"condition": ["A_gt_B"], "agent": [1], "n_episodes": [5], "n_reached": [2]})
    tests = reach_tests(reach)
    assert len(tests) == 2 and tests["p"].isna().all() and tests["reason"].str.contains("no bot episode").all()
    with pytest.raises(ValueError, match="contrast"):
        bot_reach_counts(reach, "speed")


def test_fisher_row_and_rates_agree_and_an_empty_group_is_said():
    row = fisher_row("a", "b", 8, 10, 2, 10).iloc[0]
    assert (row["effect"], row["p"]) == pytest.approx(fisher_rates(8, 10, 2, 10))
    assert row["statistic"] == pytest.approx(16.0)  # odds ratio (8/2) / (2/8)
    assert "no trials" in fisher_row("a", "b", 0, 0, 2, 10)["reason"].item()
    with pytest.raises(ValueError, match="empty group"):
        fisher_rates(1, 0, 1, 2)
