"""The decoder and the decoded variables (efish.analysis.decoding) with planted answers: a readout the state carries
scores near 1 on every held-out episode, noise and unrelated episode constants about 0 or below, episodes are held
out whole, the tables have their declared columns, and the mean Fig 6 draws is the mean of the episodes C18 and C19
test."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

from efish.analysis._tables import DEFAULTS
from efish.analysis.decoding import (
    DECODE_TARGETS,
    DECODED_COLUMNS,
    LOG_DISTANCES,
    READOUT_TARGETS,
    SENSED_TARGETS,
    SKILL_COLUMNS,
    SUMMARY_COLUMNS,
    decode_episodes,
    decoded_value,
    food_decode_episodes,
    heldout_skill,
    heldout_skills,
    summarise,
)
from efish.analysis.registry import run
from efish.rollout.schema import COLUMNS

from ..helpers import cfg_with, conditions_of, recorded_table, rollout_tables


def planted(rng, n_episodes=12, per=50, d=20):
    x = rng.normal(size=(n_episodes * per, d))
    return x, np.repeat(np.arange(n_episodes), per)


def frames(x: np.ndarray, episodes: np.ndarray, agents: int = 1, **columns) -> tuple[pd.DataFrame, pd.DataFrame]:
    """A hidden table of the rows of ``x`` (``agents`` agents taking turns within each episode) and its steps table
    with ``columns``."""
    agent = np.arange(len(x)) % agents
    t = pd.Series(np.arange(len(x))).groupby([episodes, agent]).cumcount().to_numpy()
    hidden = pd.DataFrame(x, columns=[f"h_{i}" for i in range(x.shape[1])]).assign(
        condition="control", episode=episodes, agent=agent, t=t)
    return hidden, hidden[["condition", "episode", "agent", "t"]].assign(**columns)


def test_a_planted_readout_has_skill_near_1_on_every_held_out_episode():
    rng = np.random.default_rng(0)
    x, groups = planted(rng)
    out = heldout_skill(x, x @ rng.normal(size=20) + 0.01 * rng.normal(size=len(x)), groups)
    assert list(out.columns) == SKILL_COLUMNS and out["episode"].tolist() == list(range(12))
    assert out["skill"].min() > 0.99 and (out["folds"] == 5).all() and (out["reason"] == "").all()
    angle = np.arctan2(x[:, 1], x[:, 0])  # a circular target; its cos and sin are not linear in x,
    circ = heldout_skill(np.c_[x, np.cos(angle), np.sin(angle)], angle, groups, circular=True)  # unless given
    assert circ["skill"].min() > 0.99


def test_targets_decoded_together_get_each_the_readout_it_gets_alone():
    """Targets sharing their finite rows share each fold's least-squares fit; every target's table is the one
    heldout_skill gives it alone (to rounding), whatever the others: other NaN rows, circular, constant, too few
    episodes."""
    rng = np.random.default_rng(5)
    x, groups = planted(rng)
    gappy = x @ rng.normal(size=20)
    gappy[rng.random(len(x)) < 0.2] = np.nan  # other finite rows: a fit of its own
    targets = {"linear": (x @ rng.normal(size=20) + rng.normal(size=len(x)), False),
               "angle": (np.arctan2(x[:, 1], x[:, 0]), True), "noise": (rng.normal(size=len(x)), False),
               "gappy": (gappy, False), "constant": (np.full(len(x), 2.0), False),
               "one episode": (np.where(groups == 3, 1.0, np.nan), False)}
    together = heldout_skills(x, targets, groups)
    assert list(together) == list(targets)
    for name, (y, circular) in targets.items():
        alone = heldout_skill(x, y, groups, circular)
        pd.testing.assert_frame_equal(together[name], alone, rtol=1e-9, atol=1e-12, obj=name)
    assert together["constant"]["reason"].item() == "constant target"
    assert together["one episode"]["reason"].item().startswith("fewer than 2 groups")


def test_noise_has_no_skill_and_an_episode_constant_leaks_only_when_episodes_are_split():
    rng = np.random.default_rng(0)
    x, groups = planted(rng)
    noise = heldout_skill(x, rng.normal(size=len(x)), groups)["skill"]
    assert abs(noise.mean()) < 0.15 and noise.max() < 0.2
    # the state carries which episode it is in (an offset per episode), the target is an unrelated constant per
    # episode: a readout fitted on an episode's other steps reads it off the offset, one fitted on other episodes
    # cannot
    offset = rng.normal(size=(12, 20))[groups]
    constant = rng.normal(size=12)[groups]
    whole = heldout_skill(x + 10 * offset, constant, groups)["skill"]
    split = heldout_skill(x + 10 * offset, constant, np.arange(len(x)) % 5)["skill"]  # every episode in every fold
    assert whole.mean() < 0.0 and split.min() > 0.95


def test_folds_hold_out_every_episode_whole_with_all_its_agents():
    """Each episode is scored once, on all its rows (two agents' steps pooled): it was in one test fold whole."""
    rng = np.random.default_rng(1)
    x, groups = planted(rng, n_episodes=7, per=60, d=5)
    hidden, steps = frames(x, groups, agents=2, dist_agent_cm=10 ** (1.5 + 0.2 * x[:, 0]))  # log10 linear in x
    table = decode_episodes(hidden, steps, {"dist_agent_cm": False}, folds=3)
    assert table["episode"].tolist() == list(range(7)) and (table["n"] == 60).all() and (table["folds"] == 3).all()
    assert table["skill"].min() > 0.99


def test_degenerate_inputs_give_one_row_with_a_reason():
    rng = np.random.default_rng(0)
    x, groups = planted(rng, n_episodes=3)
    one = heldout_skill(x, x[:, 0], np.zeros(len(x)))
    assert len(one) == 1 and np.isnan(one.loc[0, "skill"]) and one.loc[0, "reason"].startswith("fewer than 2 groups")
    assert heldout_skill(x, np.ones(len(x)), groups).loc[0, "reason"] == "constant target"
    nan_y = x[:, 0].copy()
    nan_y[:10] = np.nan
    out = heldout_skill(x, nan_y, groups)
    assert out["n"].tolist() == [40, 50, 50] and (out["folds"] == 3).all() and out["skill"].min() > 0.9
    all_nan = heldout_skill(np.c_[x, np.full(len(x), np.nan)], x[:, 0], groups)
    assert np.isnan(all_nan.loc[0, "skill"]) and all_nan.loc[0, "n"] == 0 and all_nan.loc[0, "reason"] != ""
    with pytest.raises(ValueError, match="differ in length"):
        heldout_skill(x, x[:-1, 0], groups)


def test_input_copies_are_readouts_and_every_target_is_a_steps_column():
    """Decoding rule (docs/claims/index.md#rule-7): the network's own last action and size, and the two summaries the
    rollout computes from its observation, are readouts; the rest are world variables, ranked (claim C19)."""
    assert set(SENSED_TARGETS).isdisjoint(READOUT_TARGETS)
    assert DECODE_TARGETS == {**SENSED_TARGETS, **READOUT_TARGETS}
    assert set(READOUT_TARGETS) == {"turn_rad", "eod", "size", "knollen_spikes", "log_morm_sensed"}
    assert {"dist_agent_cm", "n_agents_100cm", "dist_wall_cm", "bearing_agent_rad", "err_knollen_rad",
            "log_morm_field"} <= set(SENSED_TARGETS)  # the Mormyromast field at the body centre: from the scene
    assert set(DECODE_TARGETS) <= {name for name, _, _ in COLUMNS["steps"]}
    # angles are circular; the realised turn is a small signed change, decoded as a number
    assert all(DECODE_TARGETS[c] == (c.endswith("_rad") and c != "turn_rad") for c in DECODE_TARGETS)


def test_distances_are_decoded_as_their_log10_the_scale_of_the_fields():
    """The third audit: the fields an agent senses a distance by fall as a power of it, and its inputs are
    log-normalised, so a readout is linear in the log of a distance. A state that carries log10 of the
    nearest-agent and wall distances (over two decades) decodes them perfectly; the Mormyromast field at the body
    centre, already a log, is decoded as recorded; a distance of 0 has no log and is left out."""
    rng = np.random.default_rng(4)
    x, groups = planted(rng, n_episodes=8, per=60, d=4)
    dist, wall = 10 ** (1 + 0.5 * x[:, 0]), 10 ** (0.5 + 0.4 * x[:, 1])
    hidden, steps = frames(x, groups, dist_agent_cm=dist, dist_wall_cm=wall, log_morm_field=-6 + x[:, 2])
    targets = {t: False for t in ("dist_agent_cm", "dist_wall_cm", "log_morm_field")}
    skill = decode_episodes(hidden, steps, targets).groupby("target")["skill"].min()
    assert (skill > 0.99).all(), skill
    assert set(LOG_DISTANCES) == {c for c in DECODE_TARGETS if c.startswith("dist_")}
    np.testing.assert_array_equal(decoded_value(pd.DataFrame({"dist_wall_cm": [100.0, 0.0, np.nan]}), "dist_wall_cm"),
                                  [2.0, np.nan, np.nan])
    assert decoded_value(steps, "log_morm_field").tolist() == steps["log_morm_field"].tolist()


def test_the_per_episode_table_has_its_columns_and_marks_readouts_and_missing_columns():
    rng = np.random.default_rng(0)
    x, groups = planted(rng, n_episodes=6, per=40, d=4)
    hidden, steps = frames(x, groups, dist_agent_cm=x[:, 0] + 10, eod=(x[:, 1] > 0).astype(float),
                           turn_rad=x[:, 2])
    table = decode_episodes(hidden, steps)
    assert list(table.columns) == DECODED_COLUMNS
    assert set(table["target"]) == set(DECODE_TARGETS)
    marks = table.drop_duplicates("target").set_index("target")["readout"].to_dict()
    assert marks == {t: t in READOUT_TARGETS for t in DECODE_TARGETS}
    skill = table.groupby("target")["skill"].min()
    assert skill["dist_agent_cm"] > 0.9 and skill["turn_rad"] > 0.9
    lacking = table[table["target"] == "log_morm_sensed"]
    assert len(lacking) == 1 and lacking["reason"].iloc[0] == "steps table lacks column 'log_morm_sensed'"
    assert np.isnan(lacking["episode"].iloc[0]) and np.isnan(lacking["skill"].iloc[0])


def test_only_the_given_agents_states_are_decoded():
    rng = np.random.default_rng(2)
    x, groups = planted(rng, n_episodes=5, per=40, d=3)
    hidden, steps = frames(x, groups, agents=2, dist_wall_cm=10 ** x[:, 0])
    both = decode_episodes(hidden, steps, {"dist_wall_cm": False})
    homer = decode_episodes(hidden, steps, {"dist_wall_cm": False}, agent=1)
    assert (both["n"] == 40).all() and (homer["n"] == 20).all()


def test_the_summary_pools_the_episodes_errors_so_that_a_constant_episode_does_not_swamp_it():
    rng = np.random.default_rng(3)
    x, groups = planted(rng, n_episodes=8, per=30, d=4)
    dist = 10 ** (x[:, 0] + 0.5 * rng.normal(size=len(x)))
    eod = np.where(groups == 0, 0.0, (x[:, 1] > 1.5).astype(float))  # rare, and never in episode 0
    hidden, steps = frames(x, groups, dist_agent_cm=dist, eod=eod)
    episodes = decode_episodes(hidden, steps)
    summary = summarise(episodes)
    assert list(summary.columns) == SUMMARY_COLUMNS and len(summary) == len(DECODE_TARGETS)
    row = summary.set_index("target").loc["dist_agent_cm"]
    mine = episodes[episodes["target"] == "dist_agent_cm"]
    assert row["skill"] == pytest.approx(1 - mine["sse"].sum() / mine["sse_mean"].sum())
    assert row["skill"] == pytest.approx(np.average(mine["skill"], weights=mine["sse_mean"]))
    assert row["episode_skill_median"] == pytest.approx(mine["skill"].median())
    assert row["n_episodes"] == 8 and row["n"] == len(x) and row["reason"] == "" and row["skill"] > 0.5
    # an episode without a discharge sits near the training mean: its own skill is far below 0, the pooled one is not
    silent = episodes.query("target == 'eod'").set_index("episode")["skill"]
    assert silent[0] < -2 and summary.set_index("target").loc["eod", "skill"] > 0.1 > silent.mean()
    lacking = summary.set_index("target").loc["turn_rad"]
    assert lacking["n_episodes"] == 0 and np.isnan(lacking["skill"]) and "lacks column 'turn_rad'" in lacking["reason"]


def test_food_decoding_splits_at_the_near_distance_and_scores_only_where_the_state_carries_food():
    rng = np.random.default_rng(0)
    x, groups = planted(rng, n_episodes=10, per=80)
    dist = np.where(np.arange(len(x)) % 2 == 0, rng.uniform(0, 10, len(x)), rng.uniform(20, 100, len(x)))
    dist[::7] = np.nan  # steps without food are in neither range
    near = dist <= 10
    # the hidden state carries the food distance (and bearing) only when food is near
    bearing = rng.uniform(-np.pi, np.pi, len(x))
    code = np.log10(dist)  # a distance is decoded as its log10
    x = np.c_[x, np.where(near, code, 0.0), np.where(near, np.cos(bearing), 0), np.where(near, np.sin(bearing), 0)]
    hidden, steps = frames(x, groups, dist_food_cm=dist, bearing_food_rad=bearing)
    episodes = food_decode_episodes(hidden, steps, near_cm=10.0)
    assert list(episodes.columns) == ["food", *DECODED_COLUMNS]
    table = summarise(episodes, by=("food",)).set_index(["food", "target"])
    assert table.loc[("near", "dist_food_cm"), "skill"] > 0.9 and table.loc[("near", "bearing_food_rad"), "skill"] > 0.9
    assert abs(table.loc[("far", "dist_food_cm"), "skill"]) < 0.15
    assert abs(table.loc[("far", "bearing_food_rad"), "skill"]) < 0.15
    assert table.loc[("near", "dist_food_cm"), "n"] == np.sum(near)
    assert table.loc[("far", "dist_food_cm"), "n"] == np.sum(dist > 10)
    lacking = food_decode_episodes(hidden, steps.drop(columns="dist_food_cm"), near_cm=10.0)
    assert lacking["reason"].iloc[0] == "steps table lacks column 'dist_food_cm'"


def test_food_is_near_within_the_configured_5_cm_by_default():
    assert DEFAULTS.claims_food_near_cm == 5.0  # the authors' Mormyromast food range
    rng = np.random.default_rng(0)
    x, groups = planted(rng, n_episodes=6, per=40, d=3)
    dist = np.tile(np.linspace(0.25, 12.0, 40), 6)
    hidden, steps = frames(x, groups, dist_food_cm=dist, bearing_food_rad=x[:, 0])
    table = summarise(food_decode_episodes(hidden, steps), by=("food",)).set_index(["food", "target"])
    assert table.loc[("near", "dist_food_cm"), "n"] == np.sum(dist <= 5.0)
    assert table.loc[("far", "dist_food_cm"), "n"] == np.sum(dist > 5.0)


@pytest.mark.parametrize("assay", ["wide2", "homing"])
def test_the_dynamics_analysis_draws_the_mean_of_the_episodes_the_claims_test(assay):
    """Fig 6's decoding table is the per-episode table C18 and C19 read, averaged: a panel and a claim cannot
    disagree. In homing only the homer's states are decoded."""
    tables = rollout_tables(conditions=("electric", "raycast") if assay == "homing" else ("control",),
                            n_agents=2, episodes=4, error_angles=True)
    cfg = cfg_with("scale=smoke", f"assay={assay}")
    record = conditions_of("homing") if assay == "homing" else recorded_table(("control",))
    out = run("dynamics", {**tables, "conditions": record}, cfg.analysis)
    pd.testing.assert_frame_equal(out["decoding"], summarise(out["decoding_episodes"]))
    pd.testing.assert_frame_equal(out["food_decoding"], summarise(out["food_decoding_episodes"], by=("food",)))
    homer = 1 - cfg.env.homing_target if assay == "homing" else None
    expected = decode_episodes(tables["hidden"], tables["steps"], folds=cfg.analysis.decode_folds, agent=homer)
    pd.testing.assert_frame_equal(out["decoding_episodes"], expected)
    food = food_decode_episodes(tables["hidden"], tables["steps"], cfg.analysis.claims_food_near_cm,
                                cfg.analysis.decode_folds, homer)
    pd.testing.assert_frame_equal(out["food_decoding_episodes"], food)
    rows = out["decoding_episodes"].query("target == 'dist_wall_cm'")
    steps = tables["steps"] if homer is None else tables["steps"].query("agent == @homer")
    assert rows["n"].sum() == len(steps)
