"""Sweeps (efish.sweep) and what their points share (efish.share): the grid, each point's overrides and folder, bad
input in one line, and which stages a point copies from an earlier one. The workflow's dry runs of a sweep are in
test_pipeline.py."""

from __future__ import annotations

import re
import shlex
from types import SimpleNamespace

import pytest

from efish.config import compose, run_name
from efish.layout import (
    CLAIMS_TABLE,
    analysis_table,
    assay_table,
    bench_file,
    scene_table,
    selection_table,
    stacked_seeds_table,
    stage_copy,
    top_seed_copy,
    training_file,
)
from efish.run_plan import PlanError, config_files, run_settings
from efish.share import STAGES, copy_job, stage_of
from efish.sweep import (
    check_alike,
    grid_points,
    parse_grid,
    read_grid,
    sweep_grid,
    sweep_overrides,
    sweep_runs,
)


# ------------------------------------------------------------------ the grid
def test_an_inline_grid_is_the_product_of_its_values_in_the_order_given():
    grid = parse_grid("train.lr=1e-3,3e-4 'analysis.claims_alpha=0.05,0.01'")
    assert grid == {"train.lr": ["1e-3", "3e-4"], "analysis.claims_alpha": ["0.05", "0.01"]}
    assert grid_points(grid) == [("train.lr=1e-3", "analysis.claims_alpha=0.05"),
                                 ("train.lr=1e-3", "analysis.claims_alpha=0.01"),
                                 ("train.lr=3e-4", "analysis.claims_alpha=0.05"),
                                 ("train.lr=3e-4", "analysis.claims_alpha=0.01")]


def test_a_sweep_file_maps_each_key_to_its_values_as_overrides(tmp_path):
    path = tmp_path / "sweep.yaml"
    path.write_text("scale.keep_stages: [[0.5, 1.0], []]\nscale.learning: [true, false]\ntrain.lr: [0.001]\n")
    assert sweep_grid(str(path)) == {"scale.keep_stages": ["[0.5,1.0]", "[]"], "scale.learning": ["true", "false"],
                                     "train.lr": ["0.001"]}


@pytest.mark.parametrize("text, message", [
    ("train.lr", "'train.lr' is not KEY=VALUE,VALUE,..."),
    ("train.lr=", "'train.lr=' is not KEY=VALUE,VALUE,..."),
    ("train.lr=1e-3,", "'train.lr=1e-3,' is not KEY=VALUE,VALUE,..."),
    ("=1,2", "'=1,2' is not KEY=VALUE,VALUE,..."),
    ("train.lr=1,2 train.lr=3", "train.lr is given twice"),
    ("train.lr=1,1", "train.lr lists a value twice"),
    ("  ", "no keys"),
])
def test_a_malformed_grid_is_one_line(text, message):
    with pytest.raises(PlanError, match=re.escape(message)) as caught:
        parse_grid(text)
    assert "\n" not in str(caught.value)


@pytest.mark.parametrize("text, message", [
    ("- 1\n- 2\n", "must map each key to a list of values"),
    ("train.lr: []\n", "train.lr needs a non-empty list of values"),
    ("train.lr: 0.001\n", "train.lr needs a non-empty list of values"),
    ("train.lr: [1\n", "is not YAML"),
])
def test_a_bad_sweep_file_is_one_line(tmp_path, text, message):
    path = tmp_path / "sweep.yaml"
    path.write_text(text)
    with pytest.raises(PlanError, match=re.escape(message)) as caught:
        read_grid(path)
    assert "\n" not in str(caught.value)
    with pytest.raises(PlanError, match="no sweep file"):
        sweep_grid(str(tmp_path / "missing.yaml"))


# ------------------------------------------------------------------ each point's overrides and folder
def test_each_point_follows_the_runs_overrides_in_the_folder_a_single_run_gets():
    points = sweep_overrides("smoke", ["physics.tolerance=1e-6"], {"train.lr": ["1e-3", "3e-4"]})
    assert points == [("physics.tolerance=1e-6", "train.lr=1e-3"), ("physics.tolerance=1e-6", "train.lr=3e-4")]
    runs = sweep_runs("smoke", ["physics.tolerance=1e-6"], "train.lr=1e-3,3e-4")
    assert runs == [run_settings({"scale": "smoke", "overrides": shlex.join(p)})[2] for p in points]
    assert runs == [run_name("smoke", p) for p in points]


def test_a_value_the_run_already_has_is_no_override_so_that_point_is_the_run_itself():
    """Smoke's claims_resamples is 100: that point is the smoke run's own folder, the other a folder of its own."""
    assert sweep_runs("smoke", [], "analysis.claims_resamples=100,400") == [
        "smoke", run_name("smoke", ["analysis.claims_resamples=400"])]


@pytest.mark.parametrize("overrides, sweep, message", [
    ([], "physics.nonsense=1,2", "efish config: unknown config key 'physics.nonsense'"),
    ([], "physics.tolerance=1e-6,-1", "efish config: physics.tolerance=-1.0 is out of range"),
    (["train.lr=1e-3"], "train.lr=1e-3,3e-4", "sweep: train.lr also in overrides"),
    ([], "analysis.claims_alpha=0.05,5e-2", "several points are run smoke"),
])
def test_a_bad_sweep_is_one_line(overrides, sweep, message):
    with pytest.raises(PlanError, match=re.escape(message)) as caught:
        sweep_runs("smoke", overrides, sweep)
    assert "\n" not in str(caught.value)


def test_a_sweep_makes_its_own_folders_so_it_takes_no_run_name():
    with pytest.raises(PlanError, match="leave run= out of a sweep"):
        run_settings({"scale": "smoke", "sweep": "train.lr=1e-3,3e-4", "run": "mine"})
    assert run_settings({"scale": "smoke", "sweep": "train.lr=1e-3,3e-4"})[2] == "smoke"


# ------------------------------------------------------------------ what the points share
def point(*overrides: str) -> SimpleNamespace:
    """What a stage's key reads of a point's plan (a whole RunPlan composes every assay: seconds)."""
    return SimpleNamespace(run=run_name("smoke", overrides), scale="smoke", overrides=overrides,
                           policy_recipes=tuple(config_files("policy")), cfg=compose(["scale=smoke", *overrides]))


def shared(*points: SimpleNamespace) -> dict[str, dict[str, str]]:
    return {stage.name: stage.sources(list(points)) for stage in STAGES}


def test_points_that_differ_in_analysis_settings_share_training_and_rollouts_with_the_first():
    a, b, c = point(), point("analysis.claims_alpha=0.01"), point("analysis.idi_bins=20")
    assert shared(a, b, c) == {"training": {b.run: a.run, c.run: a.run}, "rollouts": {b.run: a.run, c.run: a.run}}


def test_points_that_train_alike_share_training_but_not_their_assays():
    a, b = point("scale.max_episodes=2"), point("scale.max_episodes=3")
    assert shared(a, b) == {"training": {b.run: a.run}, "rollouts": {}}


def test_points_that_train_differently_share_nothing():
    for other in ("train.lr=1e-3", "physics.tolerance=1e-6", "scale.train_steps=400"):
        assert shared(point(), point(other)) == {"training": {}, "rollouts": {}}


def test_each_stage_names_its_own_files_and_no_analysis_or_claims():
    paths = {stage.name: re.compile(stage.paths) for stage in STAGES}
    training = [training_file("seed_1", "final.pt"), training_file("seed_2", "stage_1.pt"),
                training_file("homing", "metrics.parquet")]
    rollouts = [selection_table(1, "episodes"), assay_table("patchy4", "steps"), assay_table("wide2", "hidden"),
                f"{top_seed_copy(2)}/{assay_table('patchy4', 'food')}", f"{stage_copy(1)}/{assay_table('wide2', 'steps')}",
                stacked_seeds_table("patchy4"), scene_table("eod_walls"), bench_file("bench_physics.json"),
                "bench/bench_accuracy.png", "clips/patchy4.gif"]
    neither = [analysis_table("behaviour", "patchy4", "theil"), CLAIMS_TABLE, "analysis/selection/ranking.parquet",
               f"{top_seed_copy(2)}/{analysis_table('dynamics', 'wide2', 'plsc')}", f"{top_seed_copy(2)}/{CLAIMS_TABLE}",
               "fig3/K.png", "contact_sheet.png"]
    assert all(paths["training"].fullmatch(p) for p in training)
    assert all(paths["rollouts"].fullmatch(p) for p in rollouts)
    assert not any(paths[name].fullmatch(p) for name in paths for p in neither)
    assert not any(paths["training"].fullmatch(p) for p in rollouts)


def test_a_rule_belongs_to_the_stage_all_its_outputs_are_in():
    training, rollouts = STAGES
    assert stage_of(["results/{run}/train/seed_{seed}/final.pt", "results/{run}/train/seed_{seed}/stage_1.pt"]) \
        is training
    assert stage_of(["results/{run}/seeds/seed_{seed}/assays/{assay}/steps.parquet"]) is rollouts
    assert stage_of(["results/{run}/bench/bench_accuracy.parquet", "figures/{run}/bench/bench_accuracy.png"]) \
        is rollouts
    assert stage_of(["results/{run}/analysis/behaviour/{assay}/theil.parquet"]) is None
    assert stage_of(["results/{run}/analysis/selection/ranking.parquet",
                     "results/{run}/analysis/selection/selected_seed.txt"]) is None  # the checkpoint runs per point
    assert stage_of(["results/{run}/assays/{assay}/steps.parquet", "results/{run}/claims/claims.parquet"]) is None
    assert stage_of(["results/{run}/train/seed_{seed}/final.pt", "results/{run}/scenes/{scene}.parquet"]) is None


def test_a_share_job_copies_each_output_with_the_provenance_beside_it(tmp_path):
    source, target = tmp_path / "results/a/assays/patchy4", tmp_path / "results/b/assays/patchy4"
    source.mkdir(parents=True)
    for name, text in (("steps.parquet", "steps"), ("food.parquet", "food"), ("config.yaml", "name: smoke"),
                       ("provenance.json", "{}")):
        (source / name).write_text(text)
    copy_job([str(source / "steps.parquet"), str(source / "food.parquet")],
             [str(target / "steps.parquet"), str(target / "food.parquet")], tmp_path / "share.log")
    assert sorted(p.name for p in target.iterdir()) == ["config.yaml", "food.parquet", "provenance.json",
                                                        "steps.parquet"]
    assert (target / "food.parquet").read_text() == "food"
    assert (target / "steps.parquet").stat().st_ino != (source / "steps.parquet").stat().st_ino  # not a hard link
    assert (tmp_path / "share.log").read_text().count("copied") == 2


def test_the_points_must_agree_on_what_the_rules_declare_once():
    """The train rule's outputs (the kept stages) and the assay rule of each assay (hidden states or not)."""
    def plan(run: str, kept: tuple[int, ...], hidden: set[str]) -> SimpleNamespace:
        return SimpleNamespace(run=run, stages=SimpleNamespace(kept=kept), buildable_assays=["patchy4", "wide2"],
                               records_hidden=lambda assay: assay in hidden)

    check_alike([plan("a", (1, 2), {"wide2"}), plan("b", (1, 2), {"wide2"})])
    with pytest.raises(PlanError, match=r"runs a and b keep different training stages \(scale.keep_stages\)"):
        check_alike([plan("a", (1, 2), set()), plan("b", (), set())])
    with pytest.raises(PlanError, match="runs a and b differ in whether patchy4 records hidden states"):
        check_alike([plan("a", (), set()), plan("b", (), {"patchy4"})])
