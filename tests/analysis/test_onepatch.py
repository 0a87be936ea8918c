"""The one-patch analysis's statistic tables: roles from the condition names, role_tests (Mann-Whitney of food
by role and size class against the size-matched alone control) and reach_tests (Fisher exact of the bot assay's
reach counts), on data with the effect built in."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest
from scipy import stats as sps

from efish.analysis.onepatch import (
    ALONE,
    ALONE_CLASS,
    MATCHED_ALONE,
    SOCIAL,
    SOCIAL_SIZES,
    bot_reach_counts,
    food_from_steps,
    reach_tests,
    role_tests,
    roles,
)
from efish.analysis.stats import STAT_COLUMNS, fisher_rates, fisher_row
from efish.config import compose


def onepatch_steps(b_social: float, b_alone: float, episodes: int = 8, steps: int = 10,
                   classes=("A_gt_B", "A_lt_B")) -> pd.DataFrame:
    """Steps whose ``ate`` sums to known food: B (agent 1) eats ``b_social`` + episode in each social condition of
    ``classes``, ``b_alone`` + episode alone at the matched size; A eats 3 + episode everywhere."""
    eaten = {}
    for c in classes:
        eaten |= {(c, 0): 3, (c, 1): b_social, (MATCHED_ALONE["A", c], 0): 3, (MATCHED_ALONE["B", c], 0): b_alone}
    rows = []
    for e in range(episodes):
        for (cond, agent), k in eaten.items():
            ate = np.zeros(steps, int)
            ate[: int(k) + e % 3] = 1
            rows.append(pd.DataFrame({"condition": cond, "episode": e, "agent": agent, "t": np.arange(steps),
                                      "ate": ate}))
    return pd.concat(rows, ignore_index=True)


def test_alone_controls_match_the_sizes_of_the_assay_config():
    conditions = compose(["assay=onepatch"]).assay.conditions
    assert set(conditions) == {*SOCIAL, *ALONE}
    for cond, extra in conditions.items():
        cfg = compose(["assay=onepatch", *extra])
        if cond in ALONE:
            role, size = ALONE[cond]
            assert cfg.env.n_agents == 1 and cfg.env.sizes == [size], cond
            assert cfg.env.roles == [{"A": "resident", "B": "intruder"}[role]], cond
            assert cond == f"{role}_alone_{round(100 * size)}"
        else:
            assert tuple(cfg.env.sizes) == SOCIAL_SIZES[cond] and cfg.env.roles == ["resident", "intruder"]
    for (role, social), alone in MATCHED_ALONE.items():  # the lone agent has the size its role has in the class
        assert ALONE[alone] == (role, SOCIAL_SIZES[social]["AB".index(role)])
    assert sorted(MATCHED_ALONE.values()) == sorted(ALONE) and len(ALONE_CLASS) == len(ALONE)


def test_food_is_the_sum_of_ate_per_agent_episode():
    food = food_from_steps(onepatch_steps(5, 1))
    row = food[(food["condition"] == "A_gt_B") & (food["episode"] == 2) & (food["agent"] == 1)]
    assert row["food_eaten"].item() == 5 + 2


def test_roles_follow_the_assay_config():
    food = pd.DataFrame({"condition": ["A_gt_B", "A_gt_B", "A_alone_75", "B_alone_25", "B_alone_75",
                                       "bot0.5_B0.5_rate0_frozen"],
                         "agent": [0, 1, 0, 0, 0, 1]})
    r = roles(food)
    assert r["role"].tolist() == ["A", "B", "A", "B", "B"]
    assert r["setting"].tolist() == ["A_gt_B", "A_gt_B", "alone", "alone", "alone"]
    # B alone at 0.75 is the control of B in A_lt_B, where B is 0.75
    assert r["size_class"].tolist() == ["A_gt_B", "A_gt_B", "A_gt_B", "A_gt_B", "A_lt_B"]


def test_role_tests_compare_each_role_with_its_size_matched_alone_control():
    food = food_from_steps(onepatch_steps(b_social=6, b_alone=1))
    tests = role_tests(food)
    assert list(tests.columns) == [*STAT_COLUMNS, "role"]
    assert len(tests) == 2 * len(SOCIAL) and tests.groupby("role")["group"].apply(set).to_dict() == {
        "A": set(SOCIAL), "B": set(SOCIAL)}
    b = tests[tests["role"] == "B"].set_index("group")
    assert b.loc["A_gt_B", "control"] == "B_alone_25" and b.loc["A_lt_B", "control"] == "B_alone_75"
    assert b.loc["A_gt_B", "effect"] == pytest.approx(5.0)  # medians 6+1 and 1+1
    social = food[(food["condition"] == "A_gt_B") & (food["agent"] == 1)]["food_eaten"]
    alone = food[food["condition"] == "B_alone_25"]["food_eaten"]
    assert b.loc["A_gt_B", "p"] == pytest.approx(sps.mannwhitneyu(social, alone).pvalue)
    assert b.loc["A_gt_B", "p"] < 0.01 and b.loc["A_gt_B", "stars"] != "ns"
    a = tests[tests["role"] == "A"].set_index("group")
    assert a.loc["A_gt_B", "control"] == "A_alone_75" and a.loc["A_lt_B", "control"] == "A_alone_25"
    assert (a.loc["A_gt_B", "effect"], a.loc["A_gt_B", "n"], a.loc["A_gt_B", "n_control"]) == (0.0, 8, 8)


def test_role_tests_never_compare_across_sizes():
    """B alone at 0.75 eats much more than B alone at 0.25: each class's row sees only its own control."""
    food = food_from_steps(onepatch_steps(b_social=4, b_alone=4))
    big = food["condition"] == "B_alone_75"
    food.loc[big, "food_eaten"] += 5
    b = role_tests(food).query("role == 'B'").set_index("group")
    assert b.loc["A_gt_B", "effect"] == 0.0 and b.loc["A_lt_B", "effect"] == -5.0


def test_role_tests_say_why_there_is_no_test():
    food = food_from_steps(onepatch_steps(6, 1))
    no_b_alone = role_tests(food[food["condition"] != "B_alone_25"]).set_index(["role", "group"])
    assert np.isnan(no_b_alone.loc[("B", "A_gt_B"), "p"])
    assert "B_alone_25" in no_b_alone.loc[("B", "A_gt_B"), "reason"]
    assert np.isfinite(no_b_alone.loc[("B", "A_lt_B"), "p"])
    assert "A_eq_B" in no_b_alone.loc[("A", "A_eq_B"), "reason"]  # this table has no A = B episode
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
