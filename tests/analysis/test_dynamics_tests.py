"""The dynamics analysis's statistic tables: D_eff against group size by Knollenorgan state (size_tests) and
wideband power near vs far and smaller vs larger (power_tests), on data with the effect built in."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest
from scipy import stats as sps

from efish.analysis.dynamics import dynamics_table
from efish.analysis.dynamics_tests import (
    ROLE_COLUMNS,
    groupsize_parts,
    power_near_far,
    power_roles,
    power_tests,
    size_tests,
)
from efish.analysis.stats import STAT_COLUMNS
from efish.config.recorded import recorded_conditions

from ..helpers import conditions_of


def groupsize_configs(**renamed: str):
    """The groupsize assay's recorded conditions (N = 1-4, Knollenorgans on and off), conditions renamed as given."""
    configs = recorded_conditions(conditions_of("groupsize"))
    return {renamed.get(name, name): cfg for name, cfg in configs.items()}


def test_group_size_and_knollenorgans_come_from_the_recorded_configs_not_the_names():
    configs = groupsize_configs(n2_K="pairs", n4_noK="quartet_deaf")
    parts = groupsize_parts(pd.DataFrame({"condition": ["pairs", "quartet_deaf", "n1_K", "unrecorded"]}), configs)
    assert parts["condition"].tolist() == ["pairs", "quartet_deaf", "n1_K"]  # a condition not recorded is dropped
    assert parts["n_agents"].tolist() == [2, 4, 1] and parts["knollenorgans"].tolist() == ["K", "noK", "K"]
    named_wrong = groupsize_parts(pd.DataFrame({"condition": ["n3_K"]}), groupsize_configs(n3_K="x", n1_K="n3_K"))
    assert named_wrong["n_agents"].tolist() == [1]  # the name says 3: the config says 1


def planted_dims(slope_k: float, rng) -> pd.DataFrame:
    """D_eff per agent-episode that rises by ``slope_k`` per agent with Knollenorgans on and is flat without."""
    rows = []
    for n in (1, 2, 3, 4):
        rows += [{"condition": f"n{n}_K", "episode": e, "agent": 0, "d_eff": 3 + slope_k * n + rng.normal(0, 0.1)}
                 for e in range(6)]
        rows += [{"condition": f"n{n}_noK", "episode": e, "agent": 0, "d_eff": rng.normal(3, 1)} for e in range(6)]
    return pd.DataFrame(rows)


@pytest.mark.parametrize("slope", [1.0, -1.0, 0.0])
def test_size_tests_follow_a_planted_slope_of_d_eff_on_n_with_knollenorgans(slope):
    rng = np.random.default_rng(0)
    dims = planted_dims(slope, rng)
    table = size_tests(dims, groupsize_configs())
    assert list(table.columns[: len(STAT_COLUMNS)]) == STAT_COLUMNS and set(table["measure"]) == {"d_eff"}
    tests = table.set_index("group")
    k = dims[dims["condition"].str.endswith("_K")]
    expected = sps.spearmanr(k["condition"].str.extract(r"n(\d+)")[0].astype(int), k["d_eff"])
    assert tests.loc["K", "effect"] == pytest.approx(expected.statistic)
    assert tests.loc["K", "p"] == pytest.approx(expected.pvalue)
    if slope:
        assert np.sign(tests.loc["K", "effect"]) == np.sign(slope) and tests.loc["K", "p"] < 1e-4
    else:
        assert tests.loc["K", "p"] > 0.01
    assert tests.loc["noK", "p"] > 0.01 and tests.loc["K", "control"] == "n_agents" and tests.loc["K", "n"] == 24


def test_an_assay_of_one_group_size_gets_one_row_that_says_so():
    one = {"control": groupsize_configs()["n4_K"], "deaf": groupsize_configs()["n4_noK"]}
    other = size_tests(pd.DataFrame({"condition": ["control", "deaf"], "d_eff": [2.0, 3.0]}), one)
    assert len(other) == 1 and np.isnan(other["p"].item())
    assert "does not vary across the conditions: [4]" in other["reason"].item()


def pair(episodes: int = 8, steps: int = 120, loud_far: float = 3.0):
    """Two agents whose distance is 5 cm in the first half and 150 cm in the second; the hidden states are noise
    ``loud_far`` times larger when far apart; agent 0 is smaller and twice as loud throughout."""
    rng = np.random.default_rng(1)
    far = np.arange(steps) >= steps // 2
    frames, hidden = [], []
    for e in range(episodes):
        for agent, size in ((0, 0.3), (1, 0.7)):
            keys = {"condition": "control", "episode": e, "agent": agent, "t": np.arange(steps)}
            frames.append(pd.DataFrame({**keys, "dist_agent_cm": np.where(far, 150.0, 5.0), "size": size}))
            scale = np.where(far, loud_far, 1.0)[:, None] * (2.0 if agent == 0 else 1.0)
            hidden.append(pd.DataFrame({**keys, **{f"h_{i}": v for i, v in
                                                  enumerate((rng.normal(0, 1, (steps, 4)) * scale).T)}}))
    return pd.concat(hidden, ignore_index=True), pd.concat(frames, ignore_index=True)


def test_power_near_far_and_its_tests_find_the_built_in_effects():
    hidden, steps = pair()
    near_far = power_near_far(hidden, steps, 10.0, 100.0, 20, 10, 50.0)
    assert len(near_far) == 8 * 2 * 2 and (near_far["n_steps"] == 60).all() and (near_far["reason"] == "").all()
    wide = near_far.pivot(index=["episode", "agent"], columns="where", values="wideband_power")
    assert (wide["far"] / wide["near"]).between(9 * 0.5, 9 * 2).all()  # power scales with amplitude squared
    dims = near_far.groupby(["condition", "episode", "agent"], as_index=False)["wideband_power"].mean()
    tests = power_tests(near_far, dims, steps).set_index("measure")
    nf = tests.loc["near_far"]
    assert (nf["test"], nf["group"], nf["control"], nf["n"]) == ("wilcoxon", "far", "near", 16)
    assert nf["effect"] == pytest.approx(np.median(wide["far"] - wide["near"]))
    assert nf["p"] < 0.001
    size = tests.loc["size"]
    assert (size["test"], size["group"], size["control"], size["n"], size["n_control"]) == (
        "mann-whitney", "smaller", "larger", 8, 8)
    assert size["effect"] > 0 and size["p"] < 0.001


def test_power_tests_say_why_without_far_steps_or_size_differences():
    hidden, steps = pair()
    near_far = power_near_far(hidden, steps.assign(dist_agent_cm=5.0, size=0.5), 10.0, 100.0, 20, 10, 50.0)
    assert near_far.loc[near_far["where"] == "far", "reason"].eq("only 0 far steps, fewer than the 20-step spectrogram window").all()
    dims = near_far.groupby(["condition", "episode", "agent"], as_index=False)["wideband_power"].first()
    tests = power_tests(near_far, dims, steps.assign(size=0.5)).set_index("measure")
    assert tests["p"].isna().all()
    assert "near and far" in tests.loc["near_far", "reason"] and "sizes" in tests.loc["size", "reason"]
    with pytest.raises(ValueError, match="far_cm"):
        power_near_far(hidden, steps, 100.0, 10.0, 20, 10, 50.0)


def test_power_roles_name_the_smallest_agent_of_each_episode_and_carry_its_power():
    """In :func:`pair` agent 0 (size 0.3) is the smaller and twice as loud: its power is about 4 times the larger's
    in every episode; a third agent the size of agent 1 is larger too; an episode of one size is left out."""
    hidden, steps = pair()
    third = hidden[hidden["agent"] == 1].assign(agent=2)
    hidden = pd.concat([hidden, third], ignore_index=True)
    steps = pd.concat([steps, steps[steps["agent"] == 1].assign(agent=2)], ignore_index=True)
    steps.loc[steps["episode"] == 7, "size"] = 0.5  # one size: no smaller agent
    dims = dynamics_table(hidden, fps=50.0)
    roles = power_roles(dims, steps)
    assert list(roles.columns) == ROLE_COLUMNS and sorted(roles["episode"].unique()) == list(range(7))
    assert roles.groupby("role")["agent"].unique().map(sorted).to_dict() == {"larger": [1, 2], "smaller": [0]}
    assert roles.set_index(["episode", "agent"])["size"].loc[(0, 0)] == pytest.approx(0.3)
    wide = roles.pivot_table(index="episode", columns="role", values="wideband_power")
    assert (wide["smaller"] / wide["larger"]).between(2, 8).all()
    np.testing.assert_array_equal(roles["wideband_power"], dims.set_index(["episode", "agent"]).loc[
        pd.MultiIndex.from_frame(roles[["episode", "agent"]]), "wideband_power"])
    alike = power_roles(dims, steps.assign(size=0.5))
    assert len(alike) == 1 and alike.loc[0, "reason"] == "no episode with agents of different sizes"
