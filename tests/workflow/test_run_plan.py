"""efish.run_plan: what the workflow builds at a scale, on the shipped configs, without running Snakemake.

The DAG itself is checked by the dry runs of test_pipeline.py; here each piece of the planning has a known answer.
"""

from __future__ import annotations

import dataclasses
import shutil
from pathlib import Path

import pandas as pd
import pytest

from efish import run_plan
from efish.analysis.registry import ANALYSES
from efish.claims.registry import claim_tables
from efish.config import config_dir, run_name
from efish.figures.registry import PANELS, drawable, figures, panels_for
from efish.layout import CLAIM_PARTS, CLAIMS_TABLE, ROLLOUT_TABLES, Run, assay_table, stacked_seeds_table
from efish.run_plan import PlanError, RunPlan, Stages, keyed, run_settings

SCALES = ("smoke", "laptop", "study")


@pytest.fixture(scope="module")
def plans() -> dict[str, RunPlan]:
    """The plan of each shipped scale but paper (no cache: the tests leave no .snakemake/ behind)."""
    return {scale: RunPlan.from_config({"scale": scale}, cache=None) for scale in SCALES}


@pytest.fixture(scope="module")
def narrow() -> RunPlan:
    """The smoke scale cut to one assay and no top seeds, in a folder of its own name."""
    return RunPlan.from_config({"scale": "smoke", "overrides": "scale.assays=[patchy4] scale.top_seeds=0",
                                "run": "mine"}, cache=None)


@pytest.fixture
def config_tree(tmp_path, monkeypatch) -> Path:
    """A copy of the config tree that efish reads instead of the repository's."""
    tree = tmp_path / "config"
    shutil.copytree(config_dir(), tree)
    monkeypatch.setenv("EFISH_CONFIG_DIR", str(tree))
    return tree


def write_assay(tree: Path, name: str, conditions: str) -> None:
    (tree / f"assay/{name}.yaml").write_text(
        f"# @package _global_\nassay:\n  name: {name}\n  conditions: {conditions}\n")


# ------------------------------------------------------------------ --config
def test_the_run_is_the_scale_or_the_scale_and_a_hash_of_its_overrides_or_its_name():
    assert run_settings({}) == ("laptop", (), "laptop")
    assert run_settings({"scale": "smoke", "overrides": "train.lr=3e-4 'scale.assays=[patchy4]'"}) == (
        "smoke", ("train.lr=3e-4", "scale.assays=[patchy4]"),
        run_name("smoke", ["train.lr=3e-4", "scale.assays=[patchy4]"]))
    assert run_settings({"scale": "smoke", "overrides": "train.lr=3e-4", "run": "mine"})[2] == "mine"


@pytest.mark.parametrize("config, message", [
    ({"scal": "smoke"}, "unknown --config key(s) scal: the allowed keys are scale, overrides, run"),
    ({"scale": "smoke", "run": "a/b"}, "run='a/b' is not a folder name: use letters, digits, '_', '.' and '-'"),
    ({"scale": "huge"}, "efish config: unknown scale 'huge'"),
    ({"scale": "smoke", "overrides": "physics.tolerance=-1"}, "efish config: physics.tolerance=-1.0 is out of range"),
    ({"scale": "smoke", "overrides": "scale.assays=[nope]"}, "efish config: unknown assay 'nope'"),
    ({"scale": "smoke", "overrides": "scale.homing_seeds=0"},
     "efish config: scale.homing_seeds=0 is out of range: allowed [1, inf]"),
])
def test_bad_input_is_one_line(config, message, tmp_path):
    with pytest.raises(PlanError) as caught:
        RunPlan.from_config(config, cache=tmp_path)
    assert str(caught.value).startswith(message) and "\n" not in str(caught.value)
    assert not any(tmp_path.iterdir())  # nothing kept of a plan that failed


# ------------------------------------------------------------------ assays and policies
@pytest.mark.parametrize("scale", SCALES)
def test_the_scale_runs_its_assays_each_with_the_policies_its_conditions_name(plans, scale):
    plan = plans[scale]
    assert plan.assays == ("homing", "patchy4", "uniform4", "wide2", "square2", "ablation4", "ablation1",
                           "collective", "mute", "npatch", "food_scarcity", "onepatch", "bot", "groupsize")
    # config/assay/homing.yaml: the electric condition acts with the homing recipe, raycast with homing_raycast
    assert plan.assay_policies["homing"] == {"homing": ["electric"], "homing_raycast": ["raycast"]}
    assert all(list(plan.assay_policies[a]) == ["selected"] for a in plan.buildable_assays if a != "homing")
    assert plan.asked_assays == ("selection",)  # the one file of config/assay/ no scale runs
    assert plan.policy_recipes == ("foraging", "homing", "homing_raycast")
    assert plan.policies_of("homing") == ["homing", "homing_raycast"] and plan.policies_of("dark") == ["selected"]


def test_the_assay_rules_split_by_whether_an_assay_records_hidden_states(plans):
    plan = plans["smoke"]
    hidden, plain = (plan.by_hidden(plan.buildable_assays, h) for h in (True, False))
    assert hidden == ["homing", "patchy4", "wide2", "square2", "groupsize"]  # record_hidden: true in their files
    assert sorted(hidden + plain) == sorted(plan.buildable_assays) and "selection" in plain
    assert plan.hidden_assays == hidden


def test_a_bad_assay_policy_combination_is_one_line_naming_the_assay(config_tree):
    write_assay(config_tree, "bad", '{other: ["assay.policy=nope"]}')
    base, recipes = ["scale=smoke"], run_plan.config_files("policy")
    sizes = run_plan.policy_observation_sizes(base)
    with pytest.raises(PlanError, match=r"^assay bad asks for policies nope: choose selected or one of foraging, "
                                        r"homing, homing_raycast \(files in config/policy/\)$"):
        run_plan.assay_policies(base, "bad", recipes, sizes)
    write_assay(config_tree, "bad", '{rays: ["sensors.perception=raycast"]}')  # the selected policy is electric
    with pytest.raises(PlanError, match=r"^assay bad, condition rays: its observation has 83 values but policy "
                                        r"'selected' takes 110"):
        run_plan.assay_policies(base, "bad", recipes, sizes)
    write_assay(config_tree, "bad", '{control: ["env.nonsense=1"]}')
    with pytest.raises(PlanError, match=r"^assay bad, condition control: unknown config key 'env.nonsense'"):
        run_plan.assay_policies(base, "bad", recipes, sizes)


# ------------------------------------------------------------------ the cached check
def test_the_checked_policies_are_kept_under_a_key_of_everything_they_depend_on(config_tree, tmp_path, monkeypatch):
    cache, recipes = tmp_path / "cache", run_plan.config_files("policy")
    first = run_plan.checked_policies("smoke", [], ["patchy4"], [], recipes, cache)
    assert first == {"patchy4": {"selected": ["control"]}}
    (kept,) = cache.iterdir()
    assert kept.name.startswith("assays-") and kept.suffix == ".json"

    def composing(*args):
        raise AssertionError("a kept answer is read, not composed again")

    monkeypatch.setattr(run_plan, "assay_policies", composing)
    assert run_plan.checked_policies("smoke", [], ["patchy4"], [], recipes, cache) == first
    # another override, or any edit of the config tree, is another key: composed again
    with pytest.raises(AssertionError, match="not composed again"):
        run_plan.checked_policies("smoke", ["train.lr=3e-4"], ["patchy4"], [], recipes, cache)
    patchy4 = config_tree / "assay/patchy4.yaml"
    patchy4.write_text(patchy4.read_text() + "# an edit\n")
    with pytest.raises(AssertionError, match="not composed again"):
        run_plan.checked_policies("smoke", [], ["patchy4"], [], recipes, cache)


def test_a_bad_assay_is_never_kept_so_every_parse_finds_it(config_tree, tmp_path):
    write_assay(config_tree, "draft", '{control: ["env.nonsense=1"]}')
    cache = tmp_path / "cache"
    for _ in range(2):
        with pytest.raises(PlanError, match="^assay draft, condition control"):
            run_plan.checked_policies("smoke", [], ["patchy4"], ["draft"], run_plan.config_files("policy"), cache)
    assert not cache.exists()


# ------------------------------------------------------------------ claims and top seeds
@pytest.mark.parametrize("scale", SCALES)
def test_the_other_top_seeds_rerun_every_claim_assay_the_selected_policy_acts_in(plans, scale):
    plan = plans[scale]
    # homing acts with recipes only: the same tables for every seed, so its claims are not rerun
    assert "homing" not in plan.seed_claim_assays and "patchy4" in plan.seed_claim_assays
    assert all(plan.claims_read([a]) for a in plan.seed_claim_assays)
    assert not any(t.startswith(("assays/homing/", "analysis/homing/homing/")) for t in plan.seed_claim_tables)
    assert set(plan.seed_claim_tables) < set(plan.claim_tables) <= set(claim_tables())
    assert set(plan.top_seed_assays) == {*plan.seed_claim_assays, *plan.cfg.scale.top_seed_assays}


def test_a_rerun_runs_only_the_analyses_the_claims_read(plans):
    plan = plans["smoke"]
    for analysis in ANALYSES.values():
        for assay in plan.seed_analysis_assays(analysis):
            assert any(t.startswith(f"analysis/{analysis.name}/{assay}/") for t in plan.seed_claim_tables)
    assert set(plan.seed_analysis_assays(ANALYSES["dynamics"])) <= set(plan.hidden_assays)  # it reads hidden


@pytest.mark.parametrize("scale", SCALES)
def test_each_assay_the_top_seeds_rerun_is_one_group_of_the_seeds_that_rerun_it(plans, scale):
    """The supplement's assays: every top seed, the selected one first; a claim's assay: the other top seeds (the
    selected seed's claims are the run's own); any other assay: none."""
    plan, top = plans[scale], [3, 1, 2]
    supplement = set(plan.cfg.scale.top_seed_assays)
    for assay in plan.top_seed_assays:
        assert plan.group_seeds(assay, top) == (top if assay in supplement else [1, 2]), assay
    assert plan.group_seeds("homing", top) == [] and plan.group_seeds("patchy4", [3]) == [3]


def test_an_assay_the_top_seeds_cannot_rerun_as_a_group_is_one_line(plans):
    """Each seed of a group acts as the assay's own policy, deterministically (RunPlan.from_config checks)."""
    plan = plans["smoke"]
    scale, patchy4 = plan.cfg.scale, plan.assay_settings["patchy4"]
    homing = dataclasses.replace(plan, cfg=dataclasses.replace(plan.cfg, scale=dataclasses.replace(
        scale, top_seed_assays=["homing"])))
    with pytest.raises(PlanError, match="^assay homing: the top seeds rerun it with each seed as its own policy, but "
                                        "its assay.policy is 'homing': set assay.policy=selected"):
        homing.check_groups()
    sampled = dataclasses.replace(plan, assay_settings={**plan.assay_settings, "patchy4": dataclasses.replace(
        patchy4, deterministic=False)})
    with pytest.raises(PlanError, match="^assay patchy4: the top seeds rerun it as one group, which needs "
                                        "assay.deterministic=true$"):
        sampled.check_groups()
    dataclasses.replace(homing, cfg=dataclasses.replace(homing.cfg, scale=dataclasses.replace(
        homing.cfg.scale, top_seeds=0))).check_groups()  # no top seeds, no reruns


# ------------------------------------------------------------------ the homing recipes' draws
def test_the_homing_claims_are_decided_over_draws_of_the_homing_recipes(plans):
    """scale.homing_seeds (smoke 1, laptop 3, study 4): draw 1 is the run's own homing recipes, draw k >= 2 trains
    both again into a folder of its own, and the k-th top seed (ranking order) reruns homing with draw k, solo."""
    laptop = plans["laptop"]
    assert laptop.cfg.scale.homing_seeds == 3 and plans["study"].cfg.scale.homing_seeds == 4
    assert laptop.recipe_claim_assays == ["homing"] and laptop.drawn_recipes == ["homing", "homing_raycast"]
    assert laptop.draws == (2, 3) and plans["study"].draws == (2, 3, 4) and laptop.drawn_assays == ["homing"]
    assert laptop.draw_trainings == ["homing_draw_2", "homing_raycast_draw_2", "homing_draw_3",
                                     "homing_raycast_draw_3"]
    # ranking 3, 1, 4, 2: seed 3 is the selected one (draw 1, the run's own); seed 2, fourth, reruns no homing
    assert laptop.draw_seeds([3, 1, 4, 2]) == {1: 2, 4: 3} and laptop.draw_seeds([3]) == {}
    assert "homing" not in laptop.top_seed_assays  # never in a group: it acts with two policies per seed
    drawn = laptop.top_seed_claim_tables(True)
    assert set(drawn) - set(laptop.seed_claim_tables) == {t for t in laptop.claim_tables
                                                          if t.startswith(("assays/homing/", "analysis/"))
                                                          and "/homing/" in t}
    assert {"analysis/homing/homing/trajectory_shape.parquet", "analysis/dynamics/homing/decoding_episodes.parquet",
            "analysis/homing/homing/alignment_episodes.parquet"} <= set(drawn)
    assert laptop.top_seed_claim_tables(False) == laptop.seed_claim_tables
    assert laptop.top_seed_analysis_assays(ANALYSES["homing"]) == ["homing"]
    assert "homing" in laptop.top_seed_analysis_assays(ANALYSES["dynamics"])
    assert "homing" not in laptop.seed_analysis_assays(ANALYSES["dynamics"])  # a training stage's: no draws
    smoke = plans["smoke"]  # one draw: today's DAG
    assert smoke.draws == () and smoke.draw_trainings == [] and smoke.drawn_assays == []
    assert smoke.draw_seeds([2, 1]) == {} and smoke.top_seed_claim_tables(False) == smoke.seed_claim_tables
    assert smoke.top_seed_analysis_assays(ANALYSES["homing"]) == []


def test_draw_k_of_a_homing_recipe_trains_with_seed_offset_plus_k(plans):
    laptop = plans["laptop"]
    assert laptop.recipe_training("homing") == ("homing", "scale=laptop")  # the recipe's own seed, as before
    assert laptop.recipe_training("homing_draw_2") == ("homing", "scale=laptop train.seed=2")
    assert laptop.recipe_training("homing_raycast_draw_3") == ("homing_raycast", "scale=laptop train.seed=3")
    offset = dataclasses.replace(laptop, cfg=dataclasses.replace(laptop.cfg, scale=dataclasses.replace(
        laptop.cfg.scale, seed_offset=4)))
    assert offset.draw_args(1) == offset.policy_args and offset.policy_args.endswith(" train.seed=5")
    assert offset.draw_args(3).endswith(" train.seed=7")


@pytest.mark.parametrize("overrides, message", [
    ("scale.homing_seeds=2", "scale.homing_seeds=2 exceeds scale.top_seeds=1: the k-th top seed reruns homing with "
                             "the k-th draw of its recipes, so set scale.homing_seeds at most 1"),
    ("scale.top_seeds=0 scale.homing_seeds=2", "scale.homing_seeds=2 exceeds scale.top_seeds=0: "),
])
def test_more_draws_of_the_homing_recipes_than_top_seeds_is_one_line(overrides, message):
    """Checked once the assays' policies are known (the workflow keeps those: they are not what failed)."""
    with pytest.raises(PlanError) as caught:
        RunPlan.from_config({"scale": "smoke", "overrides": overrides}, cache=None)
    assert str(caught.value).startswith(message) and "\n" not in str(caught.value)


def test_a_scale_without_the_homing_assay_ignores_homing_seeds():
    plan = RunPlan.from_config({"scale": "smoke", "overrides": "scale.assays=[patchy4] scale.top_seeds=0 "
                                "scale.homing_seeds=5"}, cache=None)
    assert plan.drawn_recipes == [] and plan.draws == () and plan.draw_trainings == []


def test_the_top_seeds_are_read_from_the_ranking_in_its_order(tmp_path):
    ranking = tmp_path / "ranking.parquet"
    pd.DataFrame({"seed": [3, 1, 2], "score": [0.9, 0.5, 0.1]}).to_parquet(ranking)
    assert run_plan.top_seeds(ranking, 2) == [3, 1] and run_plan.top_seeds(ranking, 5) == [3, 1, 2]
    (tmp_path / "selected_seed.txt").write_text("3\n")
    assert run_plan.selected_seed(tmp_path / "selected_seed.txt") == 3
    (tmp_path / "bad.parquet").write_text("not parquet")
    with pytest.raises(ValueError, match="bad.parquet as the seed ranking"):
        run_plan.top_seeds(tmp_path / "bad.parquet", 1)


# ------------------------------------------------------------------ training stages
def test_a_last_stage_at_fraction_one_is_the_final_policy_without_a_copy():
    stages = Stages.of([0.25, 0.5, 0.75, 1.0], stage_episodes=8, max_episodes=24)
    assert stages.kept == (1, 2, 3, 4) and stages.last_is_final
    assert stages.rerun == (1, 2, 3) and stages.episodes == (8, 8, 8, 24)


def test_stages_that_stop_short_of_the_end_each_get_a_copy():
    stages = Stages.of([0.3, 0.6], stage_episodes=8, max_episodes=24)
    assert stages.kept == (1, 2) and not stages.last_is_final
    assert stages.rerun == (1, 2) and stages.episodes == (8, 8)
    none = Stages.of([], stage_episodes=8, max_episodes=24)
    assert none.kept == none.rerun == none.episodes == () and not none.last_is_final


def test_the_study_scale_learns_along_training_and_the_laptop_scale_does_not(plans):
    study, laptop = plans["study"], plans["laptop"]
    assert study.stages.rerun == (1, 2, 3)  # config/scale/study.yaml: keep_stages [0.25, 0.5, 0.75, 1.0]
    run = Run("study")
    assert study.stages.parts(run) == [*(str(run.stage(k).path(CLAIM_PARTS)) for k in (1, 2, 3)),
                                      str(run.path(CLAIM_PARTS))]
    assert study.stage_args == "scale=study scale.max_episodes=8"
    assert set(study.stages.targets(run)) <= set(study.targets(run))
    # one figure per figure of the paper's claims (efish.claims.registry.CLAIM_FIGURES)
    assert [t for t in study.stages.targets(run) if t.startswith("figures/")] == [
        f"figures/study/learning/claims_by_stage_fig{n}.{ext}" for n in range(2, 7) for ext in ("png", "pdf")]
    with pytest.raises(PlanError, match=r"^the learning target needs scale.keep_stages"):
        laptop.stages.targets(Run("laptop"))
    assert not any("/learning/" in t for t in laptop.targets(Run("laptop")))


def test_keyed_pairs_each_stage_with_its_value_and_passes_a_placeholder_through():
    assert keyed((1, 2), ["a.parquet", "b.parquet"]) == "1=a.parquet 2=b.parquet"
    assert keyed((1, 2), "<TBD>") == "<TBD>"
    with pytest.raises(ValueError):
        keyed((1, 2), ["a.parquet"])


# ------------------------------------------------------------------ figures
@pytest.mark.parametrize("scale", [*SCALES, "narrow"])
def test_the_panels_are_grouped_as_the_figures_registry_groups_them(plans, narrow, scale):
    plan = narrow if scale == "narrow" else plans[scale]
    drawn = {p.key for p in drawable(plan.cfg.scale)}
    registry = {f: kept for f, panels in figures().items() if (kept := [p for p in panels if p.key in drawn])}
    assert plan.figure_panels == registry and list(plan.figure_panels) == list(registry)
    assert sum(map(len, plan.figure_panels.values())) == len(drawn)
    assert len(drawn) == (len(PANELS) if plan is not narrow else len(panels_for(["patchy4"])))


def test_a_figure_job_reads_its_panels_tables_and_writes_each_panel_and_its_page(plans):
    plan, run = plans["smoke"], Run("smoke")
    fig3 = plan.figure_panels["fig3"]
    outputs = plan.figure_outputs("fig3", run)
    assert len(outputs) == 2 * (len(fig3) + 1) and outputs[-2:] == [str(run.page("fig3", e)) for e in ("png", "pdf")]
    inputs = plan.figure_inputs("fig3", run)
    assert inputs == sorted(set(inputs)) and all(Path(p).is_relative_to(run.results) for p in inputs)
    assert str(run.path(assay_table("patchy4", "steps"))) in inputs  # Fig 3 draws patchy4's EOD rates
    assert [name for name, _, _ in plan.figure_legend("fig3")] == [p.name for p in fig3]


# ------------------------------------------------------------------ rule all
@pytest.mark.parametrize("scale", [*SCALES, "narrow"])
def test_the_targets_hold_every_table_the_claims_read_that_the_scale_produces(plans, narrow, scale):
    plan = narrow if scale == "narrow" else plans[scale]
    run = Run(plan.run)
    targets = plan.targets(run)
    assert len(targets) == len(set(targets))
    assert {str(run.path(p)) for p in plan.claim_tables} <= set(targets)
    assert {str(run.path(assay_table(a, t))) for a in plan.assays for t in ROLLOUT_TABLES} <= set(targets)
    hidden = {t for t in targets if t.endswith("/hidden.parquet")}
    assert hidden == {str(run.path(assay_table(a, "hidden"))) for a in plan.hidden_assays}
    stacked = {str(run.path(stacked_seeds_table(a))) for a in plan.cfg.scale.top_seed_assays}
    assert stacked <= set(targets) if plan.cfg.scale.top_seeds else not stacked & set(targets)
    assert {str(run.path(CLAIMS_TABLE)), str(run.contact_sheet)} <= set(targets)
    assert {t for t in targets if "/clips/" in t} == {str(run.clip(a)) for a in plan.clip_assays}
    assert all(str(run.page(f, "pdf")) in targets for f in plan.figure_panels)


def test_a_narrower_scale_asks_for_less_in_its_own_folder(narrow):
    plan = narrow
    targets = plan.targets(Run(plan.run))
    assert plan.assays == ("patchy4",) and plan.clip_assays == ["patchy4"]
    assert all(t.startswith(("results/mine/", "figures/mine/")) for t in targets)
    assert not any("homing" in t for t in targets)  # neither its assay, its analysis nor its clip
    assert len(plan.figure_panels) < len(figures())  # the figures drawn from other assays alone are left out


def test_the_top_seeds_rerun_at_fewer_episodes_where_the_scale_caps_them(plans):
    """The recipe's verdict wants more seeds at fewer episodes: the top seeds' reruns get scale.top_seed_episodes
    (study: 12 of its 24), and no extra override where the cap is no lower than max_episodes (smoke's 2)."""
    assert plans["study"].top_seed_args == "scale=study scale.max_episodes=12"
    assert plans["laptop"].top_seed_args == "scale=laptop scale.max_episodes=6"
    assert plans["smoke"].top_seed_args == plans["smoke"].args


def test_a_seed_offset_trains_a_disjoint_set_of_seeds():
    """scale.seed_offset (the stability run): the same recipe's seeds offset+1..offset+seeds, trained, selected
    and drawn under their own numbers."""
    plan = RunPlan.from_config({"scale": "smoke", "overrides": "scale.seed_offset=2", "run": "other"}, cache=None)
    assert plan.seeds == [3, 4]
    inputs = [path for figure in plan.figure_panels for path in plan.figure_inputs(figure, Run("other"))]
    assert any("train/seed_3/" in t for t in inputs) and any("train/seed_4/" in t for t in inputs)
    assert not any("train/seed_1/" in t or "train/seed_2/" in t for t in inputs)
    # the homing policies are drawn anew too (seed 3), while a run without an offset keeps the recipe's own seed
    assert plan.policy_args == "scale=smoke scale.seed_offset=2 train.seed=3"
    assert RunPlan.from_config({"scale": "smoke"}, cache=None).policy_args == "scale=smoke"


def test_the_training_targets_are_every_seeds_and_every_recipe_an_assay_acts_with(plans, narrow):
    """What a sweep's rule all asks of each point, so that a point that copies its training has all of it."""
    assert plans["smoke"].training_targets(Run("smoke")) == [
        "results/smoke/train/seed_1/final.pt", "results/smoke/train/seed_2/final.pt",
        "results/smoke/train/homing/final.pt", "results/smoke/train/homing_raycast/final.pt"]
    assert narrow.training_targets(Run("mine")) == ["results/mine/train/seed_1/final.pt",
                                                     "results/mine/train/seed_2/final.pt"]
    # the later draws of the homing recipes too: they train beside the seeds, before the seed selection
    assert plans["laptop"].training_targets(Run("laptop"))[-4:] == [
        f"results/laptop/train/{name}/final.pt" for name in plans["laptop"].draw_trainings]
