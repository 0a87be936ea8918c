"""The one-patch analysis's statistic tables: roles and matched controls from the recorded conditions, role_tests
(Mann-Whitney of food by role and size class against the size-matched alone control) and reach_tests (Fisher exact
of the bot assay's reach counts), on data with the effect built in."""

from __future__ import annotations

import dataclasses

import numpy as np
import pandas as pd
import pytest
from scipy import stats as sps

from efish.analysis.onepatch import (
    alone_conditions,
    bot_conditions,
    bot_reach_counts,
    food_from_steps,
    matched_alone,
    onepatch_roles,
    reach_tests,
    role_tests,
    roles,
    social_conditions,
)
from efish.analysis.stats import STAT_COLUMNS, fisher_rates, fisher_row
from efish.rollout.assay import condition_configs

#: What config/assay/onepatch.yaml sets: the social conditions' sizes (A, B) and each alone condition's (role, size).
SOCIAL_SIZES = {"A_gt_B": (0.75, 0.25), "A_eq_B": (0.5, 0.5), "A_lt_B": (0.25, 0.75)}
ALONE = {f"{role}_alone_{round(100 * size)}": (role, size) for role in "AB" for size in (0.25, 0.5, 0.75)}
MATCHED_ALONE = {("A", "A_gt_B"): "A_alone_75", ("A", "A_eq_B"): "A_alone_50", ("A", "A_lt_B"): "A_alone_25",
                 ("B", "A_gt_B"): "B_alone_25", ("B", "A_eq_B"): "B_alone_50", ("B", "A_lt_B"): "B_alone_75"}


@pytest.fixture(scope="module")
def onepatch():
    """The one-patch conditions as a run without overrides resolves them."""
    return condition_configs(["scale=smoke", "assay=onepatch"])


@pytest.fixture(scope="module")
def bot():
    return condition_configs(["scale=smoke", "assay=bot"])


def with_env(configs, **changes):
    """``configs`` with ``changes`` (condition -> dict of env fields) applied: what a run override records."""
    return {c: dataclasses.replace(cfg, env=dataclasses.replace(cfg.env, **changes[c])) if c in changes else cfg
            for c, cfg in configs.items()}


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


def test_roles_sizes_and_matched_controls_come_from_the_recorded_conditions(onepatch):
    assert social_conditions(onepatch) == ["A_gt_B", "A_eq_B", "A_lt_B"]  # B's size rising
    assert alone_conditions(onepatch) == ALONE
    assert matched_alone(onepatch) == MATCHED_ALONE
    for social, sizes in SOCIAL_SIZES.items():
        assert tuple(onepatch[social].env.sizes) == sizes and onepatch_roles(onepatch)[social] == {"A": 0, "B": 1}
    for (role, social), alone in MATCHED_ALONE.items():  # the lone agent has the size its role has in the class
        assert ALONE[alone] == (role, SOCIAL_SIZES[social]["AB".index(role)])


def test_a_recorded_override_of_sizes_or_roles_moves_the_matching(onepatch):
    swapped = with_env(onepatch, A_lt_B={"roles": ["intruder", "resident"]})  # B is agent 0, at 0.25
    assert onepatch_roles(swapped)["A_lt_B"] == {"B": 0, "A": 1}
    assert matched_alone(swapped)["B", "A_lt_B"] == "B_alone_25"
    bigger = with_env(onepatch, A_lt_B={"sizes": [0.25, 0.8]})  # no B alone at 0.8
    assert ("B", "A_lt_B") not in matched_alone(bigger) and social_conditions(bigger)[-1] == "A_lt_B"


def test_food_is_the_sum_of_ate_per_agent_episode():
    food = food_from_steps(onepatch_steps(5, 1))
    row = food[(food["condition"] == "A_gt_B") & (food["episode"] == 2) & (food["agent"] == 1)]
    assert row["food_eaten"].item() == 5 + 2


def test_roles_follow_the_recorded_conditions(onepatch, bot):
    food = pd.DataFrame({"condition": ["A_gt_B", "A_gt_B", "A_alone_75", "B_alone_25", "B_alone_75",
                                       "bot0.5_B0.5_rate0_frozen"],
                         "agent": [0, 1, 0, 0, 0, 1]})
    r = roles(food, {**onepatch, **bot})
    assert r["role"].tolist() == ["A", "B", "A", "B", "B"]  # the bot condition has no A and B
    assert r["setting"].tolist() == ["A_gt_B", "A_gt_B", "alone", "alone", "alone"]
    swapped = roles(food, with_env(onepatch, A_gt_B={"roles": ["intruder", "resident"]}))
    assert swapped["role"].tolist()[:2] == ["B", "A"]


@pytest.mark.parametrize("b_social, b_alone, sign", [(6, 1, 1), (1, 6, -1), (4, 4, 0)])
def test_role_tests_compare_each_role_with_its_size_matched_alone_control(onepatch, b_social, b_alone, sign):
    """B's planted effect (more with A, less with A, none) is the sign of the test; A is never affected."""
    food = food_from_steps(onepatch_steps(b_social=b_social, b_alone=b_alone))
    tests = role_tests(food, onepatch)
    assert list(tests.columns) == [*STAT_COLUMNS, "role"]
    social = social_conditions(onepatch)
    assert len(tests) == 2 * len(social) and tests.groupby("role")["group"].apply(set).to_dict() == {
        "A": set(social), "B": set(social)}
    b = tests[tests["role"] == "B"].set_index("group")
    assert b.loc["A_gt_B", "control"] == "B_alone_25" and b.loc["A_lt_B", "control"] == "B_alone_75"
    assert b.loc["A_gt_B", "effect"] == pytest.approx(b_social - b_alone)  # medians b + 1 each
    mine = food[(food["condition"] == "A_gt_B") & (food["agent"] == 1)]["food_eaten"]
    alone = food[food["condition"] == "B_alone_25"]["food_eaten"]
    assert b.loc["A_gt_B", "p"] == pytest.approx(sps.mannwhitneyu(mine, alone).pvalue)
    assert (b.loc["A_gt_B", "p"] < 0.01) == (sign != 0)
    a = tests[tests["role"] == "A"].set_index("group")
    assert a.loc["A_gt_B", "control"] == "A_alone_75" and a.loc["A_lt_B", "control"] == "A_alone_25"
    assert (a.loc["A_gt_B", "effect"], a.loc["A_gt_B", "n"], a.loc["A_gt_B", "n_control"]) == (0.0, 8, 8)


def test_role_tests_never_compare_across_sizes(onepatch):
    """B alone at 0.75 eats much more than B alone at 0.25: each class's row sees only its own control."""
    food = food_from_steps(onepatch_steps(b_social=4, b_alone=4))
    big = food["condition"] == "B_alone_75"
    food.loc[big, "food_eaten"] += 5
    b = role_tests(food, onepatch).query("role == 'B'").set_index("group")
    assert b.loc["A_gt_B", "effect"] == 0.0 and b.loc["A_lt_B", "effect"] == -5.0


def test_role_tests_say_why_there_is_no_test(onepatch, bot):
    food = food_from_steps(onepatch_steps(6, 1))
    no_b_alone = role_tests(food[food["condition"] != "B_alone_25"], onepatch).set_index(["role", "group"])
    assert np.isnan(no_b_alone.loc[("B", "A_gt_B"), "p"])
    assert "B_alone_25" in no_b_alone.loc[("B", "A_gt_B"), "reason"]
    assert np.isfinite(no_b_alone.loc[("B", "A_lt_B"), "p"])
    assert "A_eq_B" in no_b_alone.loc[("A", "A_eq_B"), "reason"]  # this table has no A = B episode
    unmatched = role_tests(food, with_env(onepatch, A_lt_B={"sizes": [0.25, 0.8]})).set_index(["role", "group"])
    assert "no B alone condition at B's size in A_lt_B" in unmatched.loc[("B", "A_lt_B"), "reason"]
    no_social = role_tests(pd.DataFrame({"condition": ["bot0.5_B0.5_rate0_frozen"], "agent": [1],
                                         "food_eaten": [1.0]}), bot)
    assert len(no_social) == 1 and "no one-patch condition" in no_social["reason"].item()


def test_bot_conditions_read_the_trained_agent_rate_and_mobility(bot):
    rows = bot_conditions(bot).set_index("condition")
    assert len(rows) == len(bot) and set(rows["agent"]) == {1}
    row = rows.loc["bot0.25_B0.75_rate0.5_frozen"]
    assert (row["bot_size"], row["agent_size"], row["bot_eod_rate"], row["mobility"]) == (0.25, 0.75, 0.5, "frozen")
    assert rows.loc["bot0.25_B0.75_rate0.5_moving", "mobility"] == "moving"


def bot_reach(k: dict[tuple[str, bool], int], n: int = 10) -> pd.DataFrame:
    """A reach_rates table of the bot assay: B (agent 1) reached k[(motion, emitting)] of n episodes."""
    rows = []
    for rate in (0, 0.5, 1):
        for motion in ("frozen", "moving"):
            cond = f"bot0.5_B0.5_rate{rate:g}_{motion}"
            rows += [{"condition": cond, "agent": 1, "n_episodes": n, "n_reached": k[(motion, rate > 0)]},
                     {"condition": cond, "agent": 0, "n_episodes": n, "n_reached": n}]  # the bot: never counted
    return pd.DataFrame(rows)


def test_reach_tests_pool_the_trained_agents_episodes_and_run_fisher(bot):
    reach = bot_reach({("frozen", True): 9, ("frozen", False): 5, ("moving", True): 4, ("moving", False): 0})
    counts = bot_reach_counts(reach, bot, "mobility")
    assert counts.loc["frozen"].tolist() == [9 + 9 + 5, 30] and counts.loc["moving"].tolist() == [8, 30]
    # a run that makes agent 1 the bot counts agent 0, who reached in every episode
    swapped = with_env(bot, **{c: {"bots": [1], "frozen": [1] * (c.endswith("frozen"))} for c in bot})
    assert bot_reach_counts(reach, swapped, "mobility")["n_reached"].tolist() == [30, 30]
    tests = reach_tests(reach, bot).set_index("contrast")
    mob = tests.loc["mobility"]
    assert (mob["group"], mob["control"], mob["n"], mob["n_control"]) == ("frozen", "moving", 30, 30)
    assert mob["effect"] == pytest.approx(23 / 30 - 8 / 30)
    assert mob["p"] == pytest.approx(sps.fisher_exact([[23, 7], [8, 22]]).pvalue)
    eod = tests.loc["eod"]  # emitting: rates 0.5 and 1, 40 episodes; silent: rate 0, 20 episodes
    assert (eod["group"], eod["n"], eod["n_control"]) == ("emitting", 40, 20)
    assert eod["effect"] == pytest.approx(26 / 40 - 5 / 20)


def test_reach_tests_without_bot_conditions_are_nan_rows_with_a_reason(onepatch):
    reach = pd.DataFrame({"condition": ["A_gt_B"], "agent": [1], "n_episodes": [5], "n_reached": [2]})
    tests = reach_tests(reach, onepatch)
    assert len(tests) == 2 and tests["p"].isna().all() and tests["reason"].str.contains("no bot episode").all()
    with pytest.raises(ValueError, match="contrast"):
        bot_reach_counts(reach, onepatch, "speed")


def test_fisher_row_and_rates_agree_and_an_empty_group_is_said():
    row = fisher_row("a", "b", 8, 10, 2, 10).iloc[0]
    assert (row["effect"], row["p"]) == pytest.approx(fisher_rates(8, 10, 2, 10))
    assert row["statistic"] == pytest.approx(16.0)  # odds ratio (8/2) / (2/8)
    assert "no trials" in fisher_row("a", "b", 0, 0, 2, 10)["reason"].item()
    with pytest.raises(ValueError, match="empty group"):
        fisher_rates(1, 0, 1, 2)
