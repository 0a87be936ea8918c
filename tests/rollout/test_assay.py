"""Assays from config, and the select command, end to end on a tiny trained policy."""

from __future__ import annotations

import pandas as pd
import pytest

from efish.cli import main
from efish.config import compose
from efish.rl.policy import load_policy
from efish.rl.train import train
from efish.rollout.assay import run_assay

TINY_TRAIN = ["arena=collective", "env.n_agents=2", "env.episode_steps=20", "train.hidden=8", "train.num_envs=2",
              "train.rollout_steps=20", "train.chunk=5", "train.total_steps=40", "train.epochs=1"]


@pytest.fixture(scope="module")
def policy_dir(tmp_path_factory):
    out = tmp_path_factory.mktemp("train") / "seed_1"
    train(compose(TINY_TRAIN), out)
    return out


def test_every_condition_of_an_assay_lands_in_the_tables(policy_dir):
    tables = run_assay(["assay=mute", "env.episode_steps=15", "assay.episodes=2"], load_policy(policy_dir))
    s = tables["steps"]
    assert set(s["condition"]) == {"none_muted", "agent0_muted"}
    assert not s[(s.condition == "agent0_muted") & (s.agent == 0)]["eod"].any()
    assert len(tables["episodes"]) == 2 * 2 * 2  # conditions x episodes x agents


def test_assay_and_select_commands_write_their_outputs(policy_dir, tmp_path):
    for seed in (1, 2):
        assert main(["assay", "assay=patchy4", "env.n_agents=2", "env.episode_steps=10", "assay.episodes=2",
                     "--policy", str(policy_dir), "--out", str(tmp_path / f"seed_{seed}")]) == 0
        assert (tmp_path / f"seed_{seed}" / "provenance.json").exists()
    files = [str(tmp_path / f"seed_{s}" / "episodes.parquet") for s in (1, 2)]
    assert main(["select", "--episodes", *files, "--out", str(tmp_path / "select")]) == 0
    ranking = pd.read_parquet(tmp_path / "select" / "ranking.parquet")
    assert ranking["selected"].sum() == 1
    assert (tmp_path / "select" / "selected_seed.txt").read_text().strip() in {"1", "2"}


def test_assay_with_a_policy_of_another_shape_fails_clearly(policy_dir, tmp_path, capsys):
    code = main(["assay", "assay=patchy4", "sensors.perception=raycast", "assay.episodes=1", "env.episode_steps=5",
                 "--policy", str(policy_dir), "--out", str(tmp_path / "x")])
    assert code == 2 and "policy" in capsys.readouterr().err
    assert not (tmp_path / "x").exists()
