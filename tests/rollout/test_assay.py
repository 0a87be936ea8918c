"""Assays from config end to end: every intervention visible in the data, tables exact and repeatable."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

from efish.cli import main
from efish.config import ConfigError, compose
from efish.env.observe import observation_size
from efish.rl.policy import load_policy
from efish.rl.train import train
from efish.rollout.assay import condition_configs, run_assay
from efish.rollout.schema import to_table

from ..helpers import table_digest

TINY_TRAIN = ["arena=collective", "env.n_agents=2", "env.episode_steps=20", "train.hidden=8", "train.num_envs=2",
              "train.rollout_steps=20", "train.chunk=5", "train.total_steps=40", "train.epochs=1"]
SHORT = ["scale=smoke", "scale.max_episode_steps=12", "scale.max_episodes=2"]


class Scripted:
    """Full speed ahead, always emit and bite; a GRU-like state of 3 units that counts steps."""

    def __init__(self, obs_dim: int):
        self.obs_dim = obs_dim

    def initial_hidden(self, b, n):
        return np.zeros((b, n, 3), np.float32)

    def act(self, obs, hidden, starts, deterministic=True):
        assert obs.shape[-1] == self.obs_dim
        a = np.ones(obs.shape[:2] + (4,))
        a[..., 0] = 40.0
        return a, hidden + 1


SCRIPTED = {"selected": Scripted(110), "homing": Scripted(110), "homing_raycast": Scripted(83)}


@pytest.fixture(scope="module")
def policy_dir(tmp_path_factory):
    out = tmp_path_factory.mktemp("train") / "seed_1"
    train(compose(TINY_TRAIN), out)
    return out


@pytest.fixture(scope="module")
def assays():
    """Every assay of the paper, short, with scripted policies."""
    names = ["homing", "wide2", "mute", "ablation4", "onepatch", "bot", "groupsize"]
    return {name: run_assay([f"assay={name}", *SHORT], SCRIPTED)[0] for name in names}


def test_interventions_are_visible_in_the_data(assays):
    mute = assays["mute"]["steps"]
    # the Results' design mutes agent 1 of 2, the Methods' agent 0 of 4
    assert not mute[(mute.condition == "muted") & (mute.agent == 1)]["eod"].any()
    assert mute[(mute.condition == "intact") & (mute.agent == 1)]["eod"].all()
    assert not mute[(mute.condition == "muted4") & (mute.agent == 0)]["eod"].any()
    assert mute[(mute.condition == "intact4") & (mute.agent == 0)]["eod"].all()
    assert mute.groupby("condition")["agent"].nunique().to_dict() == {"intact": 2, "muted": 2, "intact4": 4,
                                                                      "muted4": 4}
    ablation = assays["ablation4"]["steps"].set_index("condition")
    assert (ablation.loc["A_K", "morm_abs_mean"] == 0).all() and (ablation.loc["M_K", "amp_abs_mean"] == 0).all()
    assert (ablation.loc["M_A", "knollen_spikes"] == 0).all() and (ablation.loc["none", "n_knollen_agents"] == 0).all()
    bot = assays["bot"]["steps"]
    step = 0.35 * 2 * (1 + bot["size"].max()) * 100 / 83
    bots = bot[bot.agent == 0]
    assert (np.hypot(bots.x_cm - 75, bots.y_cm - 75) <= 8.5 + step + 1e-4).all()
    assert not bots["ate"].any() and not bots["bit"].any()
    frozen = bots[bots.condition.str.endswith("frozen")]
    assert (frozen.groupby(["condition", "episode"])["x_cm"].nunique() == 1).all()
    groups = assays["groupsize"]["steps"].groupby(["condition", "episode", "t"])["agent"].nunique()
    assert all(groups[c].eq(int(c[1])).all() for c in groups.index.get_level_values(0).unique())
    assert set(assays["onepatch"]["steps"].query("condition == 'A_alone_75'")["agent"]) == {0}


def test_starts_follow_the_assay(assays):
    wide = assays["wide2"]["steps"].query("t == 0").sort_values(["episode", "agent"])
    start = np.array([[20.0, 20.0], [140.0, 20.0]])
    moved = np.hypot(wide.x_cm.to_numpy().reshape(-1, 2) - start[:, 0], wide.y_cm.to_numpy().reshape(-1, 2) - start[:, 1])
    assert (moved <= 0.8434 * 2 + 1e-4).all()  # one step from the start at most
    home = compose(["assay=homing"])
    for cfg in condition_configs(["assay=homing"]).values():
        from efish.env import VecEnv

        env = VecEnv(cfg, num_envs=20, seed=cfg.assay.seed)
        env.reset()
        xy = env.state.xy
        assert (np.linalg.norm(xy[:, 1] - xy[:, 0], axis=-1) >= home.env.homing_min_distance_cm).all()
        assert (xy >= 5).all() and (xy <= 65).all()
    one = assays["onepatch"]["steps"].query("condition == 'A_eq_B' and t == 0").pivot(index="episode",
                                                                                         columns="agent")
    gap = np.hypot(one["x_cm"][1] - one["x_cm"][0], one["y_cm"][1] - one["y_cm"][0])
    assert ((gap >= 20 - 2) & (gap <= 100 + 2)).all()


def test_row_counts_are_conditions_x_episodes_x_steps_x_agents(assays):
    for name, tables in assays.items():
        steps, episodes = tables["steps"], tables["episodes"]
        per_episode = steps.groupby(["condition", "episode"]).size()
        expected = episodes.groupby(["condition", "episode"]).apply(lambda e: e["steps"].max() * len(e))
        pd.testing.assert_series_equal(per_episode, expected, check_names=False)
        if name != "homing":
            assert (episodes["steps"] == 12).all(), name
        for table in tables:
            to_table(tables[table], table)  # every table validates against its schema


def test_hidden_states_are_recorded_where_the_assay_asks(assays):
    hidden = assays["wide2"]["hidden"]
    assert len(hidden) == len(assays["wide2"]["steps"])
    assert list(hidden.columns[-3:]) == ["h_0", "h_1", "h_2"] and hidden["h_0"].dtype == np.float32
    assert "hidden" not in assays["mute"]


def test_an_assay_run_twice_gives_identical_tables():
    first, _ = run_assay(["assay=onepatch", *SHORT], SCRIPTED)
    second, _ = run_assay(["assay=onepatch", *SHORT], SCRIPTED)
    assert set(first) == set(second) and "conditions" in first
    assert {k: table_digest(v) for k, v in first.items()} == {k: table_digest(v) for k, v in second.items()}


def test_an_assay_records_what_its_conditions_resolved_to():
    """conditions.parquet holds each condition as composed with the run's overrides, in the assay's order, and
    reads back to the very configs that ran (the record panels and clips draw from)."""
    from efish.config.recorded import recorded_conditions
    from efish.rollout.schema import to_table

    overrides = ["assay=onepatch", *SHORT, "env.fps=25"]
    tables, _ = run_assay(overrides, SCRIPTED)
    recorded = to_table(tables["conditions"], "conditions").to_pandas()
    configs = condition_configs(overrides)
    assert list(recorded["condition"]) == list(configs) and list(recorded["position"]) == list(range(len(configs)))
    assert (recorded["fps"] == 25).all()
    assert [list(s) for s in recorded["sizes"]] == [cfg.env.sizes for cfg in configs.values()]
    assert list(recorded.loc[recorded["condition"] == "A_lt_B", "overrides"].iloc[0]) == ["env.sizes=[0.25,0.75]"]
    assert dict(recorded_conditions(recorded)) == configs


def test_bad_conditions_and_policies_fail_before_any_step():
    with pytest.raises(ConfigError, match="condition broken"):
        condition_configs(["assay=mute", '+assay.conditions.broken=["env.nonsense=1"]'])
    with pytest.raises(ValueError, match="needs policies homing_raycast"):
        run_assay(["assay=homing", *SHORT], {"homing": Scripted(110)})
    with pytest.raises(ValueError, match="condition raycast: its observation has 83 values but policy 'homing'"):
        run_assay(["assay=homing", *SHORT, 'assay.conditions.raycast=["sensors.perception=raycast"]'],
                  {"homing": Scripted(110)})
    assert observation_size(compose(["policy=homing_raycast"])) == 83


def test_assay_and_select_commands_write_their_outputs(policy_dir, tmp_path):
    for seed in (1, 2):
        assert main(["assay", "assay=patchy4", "env.n_agents=2", *SHORT, "--policy", str(policy_dir),
                     "--out", str(tmp_path / f"seed_{seed}")]) == 0
        assert (tmp_path / f"seed_{seed}" / "hidden.parquet").exists()
    files = [str(tmp_path / f"seed_{s}" / "episodes.parquet") for s in (1, 2)]
    assert main(["select", "--episodes", *files, "--out", str(tmp_path / "select")]) == 0
    ranking = pd.read_parquet(tmp_path / "select" / "ranking.parquet")
    assert ranking["selected"].sum() == 1


def test_assay_with_a_policy_of_another_shape_fails_clearly(policy_dir, tmp_path, capsys):
    code = main(["assay", "assay=patchy4", "sensors.perception=raycast", *SHORT, "--policy", str(policy_dir),
                 "--out", str(tmp_path / "x")])
    err = capsys.readouterr().err
    assert code == 2 and "observation has 83 values but policy 'selected' takes 110" in err
    assert len(err.strip().splitlines()) == 1 and not (tmp_path / "x").exists()
    load_policy(policy_dir)


def test_a_group_of_policies_writes_each_members_tables_as_alone(policy_dir, tmp_path, capsys):
    """``efish assay --group``: the same checkpoint as two members, and a second checkpoint of another seed; each
    member's folder holds the tables its run alone writes."""
    other = tmp_path / "train2"
    train(compose([*TINY_TRAIN, "train.seed=2"]), other)
    args = ["assay", "assay=patchy4", "env.n_agents=2", *SHORT]
    assert main([*args, "--group", f"1={policy_dir}", f"2={other}", "--out", str(tmp_path / "seed_{member}")]) == 0
    for seed, path in ((1, policy_dir), (2, other)):
        assert main([*args, "--policy", str(path), "--out", str(tmp_path / f"alone_{seed}")]) == 0
        for table in ("steps", "episodes", "food", "hidden", "conditions"):
            pd.testing.assert_frame_equal(pd.read_parquet(tmp_path / f"seed_{seed}" / f"{table}.parquet"),
                                          pd.read_parquet(tmp_path / f"alone_{seed}" / f"{table}.parquet"))
        assert (tmp_path / f"seed_{seed}" / "provenance.json").exists()
    capsys.readouterr()
    assert main([*args, "--group", f"1={policy_dir}", "--out", str(tmp_path / "no_template")]) == 2
    assert "{member}" in capsys.readouterr().err and not (tmp_path / "no_template").exists()
