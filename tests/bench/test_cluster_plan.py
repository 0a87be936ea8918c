"""``efish plan-cluster`` on synthetic benchmark files: cost models, unmeasured twins, profile headroom, errors."""

from __future__ import annotations

from pathlib import Path

import pytest

from efish.bench.cluster import (
    CostModel,
    check_profile,
    format_plan,
    parse_dry_run,
    plan_jobs,
    profile_resources,
    read_benchmarks,
    suggested_resources,
)
from efish.bench.train import forward_flops

DRY_RUN = """\
Building DAG of jobs...
[Mon Nov 23 23:57:09 2026]
rule train:
    output: results/big/train/seed_1/final.pt, results/big/train/seed_1/metrics.parquet
    log: results/big/logs/train/seed_1.log
    jobid: 3
    benchmark: results/big/benchmarks/train/seed_1.tsv
    reason: Forced execution
    wildcards: run=big, seed=1
    threads: 8
    resources: tmpdir=/tmp
rule train:
    jobid: 4
    benchmark: results/big/benchmarks/train/seed_3.tsv
    wildcards: run=big, seed=3
rule assay:
    input: <TBD>
    jobid: 5
    benchmark: results/big/benchmarks/assays/patchy4.tsv
    wildcards: run=big, assay=patchy4
rule analysis_behaviour:
    jobid: 6
    benchmark: results/big/benchmarks/analysis/behaviour/patchy4.tsv
    wildcards: run=big, assay=patchy4
rule panel:
    jobid: 7
    benchmark: results/big/benchmarks/figures/fig2_B.tsv
    wildcards: run=big, figure=fig2, panel=B
rule top_seeds:
    jobid: 8
    wildcards: run=big, assay=patchy4
localrule all:
    jobid: 0
"""
HEADER = "s\th:m:s\tmax_rss\tmax_vms\tmax_uss\tmax_pss\tio_in\tio_out\tmean_load\tcpu_time\n"
MEASURED = {"train/seed_1.tsv": (300.0, 900.0, 120.0), "assays/patchy4.tsv": (50.0, 700.0, 30.0),
            "analysis/behaviour/patchy4.tsv": (20.0, 500.0, "NA"), "figures/fig2_B.tsv": (5.0, 400.0, 4.0)}
PROFILE = """\
default-resources:
  runtime: 10
  mem_mb: 2000
set-threads:
  train: 8
set-resources:
  train:
    runtime: 60
    mem_mb: 4000
    cpus_per_task: 8
  assay:
    runtime: 1
"""
SOURCE = ["scale=smoke"]
TARGET = ["scale=smoke", "scale.train_steps=400", "scale.max_episodes=4", "scale.hidden=32"]


def write_benchmarks(folder: Path) -> Path:
    for key, (wall, rss, cpu) in MEASURED.items():
        path = folder / "benchmarks" / key
        path.parent.mkdir(parents=True, exist_ok=True)
        path.write_text(HEADER + f"{wall}\t0:00:00\t{rss}\t1\t1\t1\t0\t0\t50\t{cpu}\n")
    return folder


@pytest.fixture(scope="module")
def checked(tmp_path_factory):
    folder = write_benchmarks(tmp_path_factory.mktemp("laptop"))
    profile = tmp_path_factory.mktemp("profile") / "config.yaml"
    profile.write_text(PROFILE)
    plan = plan_jobs(parse_dry_run(DRY_RUN), read_benchmarks(folder / "benchmarks"), CostModel(SOURCE),
                     CostModel(TARGET))
    return check_profile(plan, profile_resources(profile)).set_index("job")


def test_the_dry_run_gives_every_job_but_the_local_ones():
    jobs = parse_dry_run(DRY_RUN)
    assert [j.rule for j in jobs] == ["train", "train", "assay", "analysis_behaviour", "panel", "top_seeds"]
    assert jobs[0].wildcards == {"run": "big", "seed": "1"} and jobs[0].benchmark == "train/seed_1.tsv"
    assert jobs[-1].benchmark is None


def test_cpu_time_is_the_cost_and_the_wall_time_its_fallback(tmp_path):
    table = read_benchmarks(write_benchmarks(tmp_path) / "benchmarks").set_index("key")
    assert table.loc["train/seed_1.tsv", "seconds"] == 120.0  # cpu_time, not the 300 s of wall time
    assert table.loc["analysis/behaviour/patchy4.tsv", "seconds"] == 20.0  # no cpu_time: the wall time


def test_training_scales_by_env_steps_and_model_flops(checked, cfg_factory):
    from efish.env.observe import observation_size

    cfg = cfg_factory("scale=smoke")
    d, n = observation_size(cfg), cfg.env.n_agents
    flops = {w: forward_flops(d, w, 4) + forward_flops(d * n, w, 1) for w in (16, 32)}
    ratio = 2 * flops[32] / flops[16]  # twice the env steps, at twice the width
    row = checked.loc["seed=1"]
    assert row["work_ratio"] == pytest.approx(ratio)
    assert row["runtime_min"] == pytest.approx(120.0 * ratio / 60)
    # memory above the smallest resident set (400 MB) grows with the rollout buffer, here with the width only
    buffer = {w: cfg.train.num_envs * cfg.train.rollout_steps * n * (d * (1 + n) + 2 * w) for w in (16, 32)}
    assert row["mem_mb"] == pytest.approx(400 + 500 * buffer[32] / buffer[16])
    # seed 3 was not measured: it takes seed 1's estimate
    assert checked.loc["seed=3", "runtime_min"] == pytest.approx(row["runtime_min"])
    assert row["cores"] == 8 and row["profile_runtime_min"] == 60


def test_assays_and_their_analyses_scale_by_agent_steps(checked):
    # twice the episodes per condition (smoke caps patchy4 at 2, the target at 4)
    assert checked.loc["assay=patchy4"].query("rule == 'assay'")["runtime_min"].iloc[0] == pytest.approx(2 * 30 / 60)
    analysis = checked[checked["rule"] == "analysis_behaviour"].iloc[0]
    assert analysis["work_ratio"] == pytest.approx(2.0) and analysis["runtime_min"] == pytest.approx(2 * 20 / 60)
    panel = checked.loc["figure=fig2,panel=B"]
    assert panel["work_ratio"] == 1.0 and panel["runtime_min"] == pytest.approx(4 / 60)  # as measured


def test_the_profile_check_flags_rules_without_headroom(checked):
    train = checked.loc["seed=1"]
    assert train["runtime_headroom"] == pytest.approx(60 / train["runtime_min"]) and train["ok"]
    assay = checked[checked["rule"] == "assay"].iloc[0]
    assert assay["profile_runtime_min"] == 1 and not assay["ok"]  # 1 min < 1.5 x 1 min
    assert checked.loc["figure=fig2,panel=B", "ok"]  # defaults: 10 min, 2000 MB
    top = checked[checked["rule"] == "top_seeds"].iloc[0]
    assert not top["measured"] and top["ok"]
    text = format_plan(checked.reset_index())
    assert text.endswith("the profile leaves less than 1.5x headroom for: assay")
    assert "6 jobs, 5 with a measured counterpart" in text
    suggested = suggested_resources(checked.reset_index())
    assert suggested["assay"]["runtime"] >= 1.5 * assay["runtime_min"]
    assert suggested["train"]["mem_mb"] >= 1.5 * checked.loc["seed=1", "mem_mb"]


def test_efish_plan_cluster_prints_the_plan_and_names_missing_benchmarks(tmp_path, capsys):
    from efish.cli import main

    write_benchmarks(tmp_path / "laptop")
    (tmp_path / "dry.txt").write_text(DRY_RUN)
    (tmp_path / "profile.yaml").write_text(PROFILE)
    args = ["plan-cluster", *TARGET, "--from", "smoke", "--dry-run", str(tmp_path / "dry.txt"), "--profile",
            str(tmp_path / "profile.yaml")]
    assert main([*args, "--results", str(tmp_path / "laptop"), "--suggest"]) == 0
    out = capsys.readouterr().out
    assert "runtime_headroom" in out and "set-resources:" in out
    assert main([*args, "--results", str(tmp_path / "none")]) == 2
    assert capsys.readouterr().err.startswith("efish: error: no Snakemake benchmark files under")


def test_a_top_seed_group_scales_with_its_seeds_and_its_links_are_taken_as_measured():
    """One grouped job rolls out every top seed that reruns the assay: its work is the assay's agent-steps times
    the group's seeds (all top seeds for the supplement's assays, the others for a claim's); the per-seed jobs
    that only link the group's tables do not scale."""
    from efish.bench.cluster import Job

    model = CostModel(["scale=laptop"])
    scale = model._cfg().scale
    supplement, claim = scale.top_seed_assays[0], "ablation4"
    assert claim not in scale.top_seed_assays
    for assay, seeds in ((supplement, scale.top_seeds), (claim, scale.top_seeds - 1)):
        work, memory = model.units(Job("top_seed_group", {"run": "laptop", "assay": assay}, None))
        assert work == memory == pytest.approx(model._assay_steps(assay) * seeds)
    assert model.units(Job("top_seed_assay", {"run": "laptop", "seed": "2", "assay": claim}, None)) is None


def test_a_later_draw_of_a_homing_recipe_is_priced_as_its_recipes_training(tmp_path):
    """scale.homing_seeds: train/homing_draw_2 is the homing recipe trained with another seed, and a top seed's solo
    rerun of homing with its draw is the run's homing assay again; a draw never measured takes the measured
    recipe trainings' estimate."""
    from efish.bench.cluster import Job

    model = CostModel(["scale=smoke"])
    for recipe in ("homing", "homing_raycast"):
        assert model.units(Job("train_policy", {"run": "x", "policy": f"{recipe}_draw_2"}, None)) == model.units(
            Job("train_policy", {"run": "x", "policy": recipe}, None))
    homing = model.units(Job("assay_with_hidden", {"run": "x", "assay": "homing"}, None))
    assert homing and model.units(Job("top_seed_recipe_assay_with_hidden",
                                      {"run": "x", "seed": "1", "assay": "homing"}, None)) == homing
    dry = ("rule train_policy:\n    benchmark: results/big/benchmarks/train/homing.tsv\n"
           "    wildcards: run=big, policy=homing\n"
           "rule train_policy:\n    benchmark: results/big/benchmarks/train/homing_draw_2.tsv\n"
           "    wildcards: run=big, policy=homing_draw_2\n")
    path = tmp_path / "benchmarks/train/homing.tsv"
    path.parent.mkdir(parents=True)
    path.write_text(HEADER + "100\t0:00:00\t800\t1\t1\t1\t0\t0\t50\t90\n")
    plan = plan_jobs(parse_dry_run(dry), read_benchmarks(tmp_path / "benchmarks"), model,
                     CostModel(["scale=smoke", "scale.homing_steps=400"])).set_index("job")
    assert plan.loc["policy=homing_draw_2", "measured"]
    assert plan.loc["policy=homing_draw_2", "runtime_min"] == pytest.approx(plan.loc["policy=homing", "runtime_min"])
    assert plan.loc["policy=homing", "work_ratio"] == pytest.approx(4.0)  # smoke's homing_steps: 100
