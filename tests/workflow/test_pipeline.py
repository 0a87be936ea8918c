"""The Snakemake pipeline at smoke scale: every rule runs and writes what it declares."""

from __future__ import annotations

import json
import os
import re
import shutil
import signal
import subprocess
import time
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

import efish
from efish.analysis.selection import RANKING_COLUMNS
from efish.bench.accuracy import COLUMNS
from efish.claims.recipe import RECIPE_PART_COLUMNS
from efish.config import run_name
from efish.layout import Run, top_seed_group
from efish.rollout.schema import SCHEMAS, check_file

from ..helpers import scratch_workflow, smoke_env

REPO = Path(__file__).resolve().parents[2]


def declared_outputs(work: Path) -> list[str]:
    """Every output file of the smoke DAG, as Snakemake itself lists them."""
    result = subprocess.run(["snakemake", "--config", "scale=smoke", "--summary", "--directory", str(work),
                             "--snakefile", str(work / "Snakefile")], capture_output=True, text=True, timeout=300,
                            env=smoke_env(work))
    assert result.returncode == 0, result.stderr[-2000:]
    return [line.split("\t")[0] for line in result.stdout.splitlines()[1:] if line.strip()]


@pytest.mark.slow
def test_every_declared_output_exists(smoke_run):
    outputs = declared_outputs(smoke_run)
    for part in ("train/seed_1/final.pt", "train/seed_2/final.pt", "train/homing/final.pt",
                 "analysis/selection/ranking.parquet", "assays/patchy4/steps.parquet",
                 "assays/homing/episodes.parquet", "analysis/behaviour/patchy4/condition_tests.parquet",
                 "analysis/homing/homing/perception.parquet"):
        assert f"results/smoke/{part}" in outputs, part
    assert any(o.startswith("figures/smoke/fig3/") for o in outputs)
    # the top seeds' group folders are temp outputs: gone once every seed has its tables
    groups = [o for o in outputs if o.startswith(f"{Run('smoke').path(top_seed_group(''))}/")]
    assert groups and not any((smoke_run / o).exists() for o in groups)
    missing = [o for o in outputs if o not in groups and not (smoke_run / o).is_file()]
    assert not missing


@pytest.mark.slow
def test_every_table_matches_its_schema(smoke_run):
    tables = list((smoke_run / "results/smoke").glob("**/*.parquet"))
    checked = 0
    for path in tables:
        if path.parent.parent.name == "seeds":  # the top seeds stacked: the schema's columns, then seed and rank
            assert list(pd.read_parquet(path).columns) == [*SCHEMAS[path.stem].names, "seed", "rank"], path
        elif path.stem in SCHEMAS:
            check_file(path, path.stem)
            checked += 1
    assert checked >= 3 * (2 + 2)  # two assays and two seed evaluations, three tables each
    ranking = pd.read_parquet(smoke_run / "results/smoke/analysis/selection/ranking.parquet")
    assert list(ranking.columns) == list(RANKING_COLUMNS)
    assert sorted(ranking["seed"]) == [1, 2] and ranking["selected"].sum() == 1
    chosen = int((smoke_run / "results/smoke/analysis/selection/selected_seed.txt").read_text())
    assert chosen == int(ranking.loc[ranking["selected"], "seed"].iloc[0])


@pytest.mark.slow
def test_every_output_folder_has_config_and_provenance(smoke_run):
    tables = list((smoke_run / "results/smoke").glob("**/*.parquet"))
    for folder in {p.parent for p in tables if p.parent.parent.name != "seeds"}:
        assert "name: smoke" in (folder / "config.yaml").read_text(), folder
    for table in tables:  # a folder of one command's tables has provenance.json, a folder of many (scenes) one each
        own = table.with_name(f"{table.stem}.provenance.json")
        if table.parent.parent.name != "seeds":
            check_provenance(own if own.is_file() else table.parent / "provenance.json")
    # figures: every drawn PNG (panels, pages, the accuracy figure) has a PDF and its own provenance
    drawn = list((smoke_run / "figures/smoke").glob("**/*.png"))
    assert any(p.parent.name == "bench" for p in drawn) and any(p.parent.name == "smoke" for p in drawn)
    for png in drawn:
        if png.stem != "contact_sheet":  # thumbnails of the panels' PNGs: a PDF would add nothing
            assert png.with_suffix(".pdf").is_file(), png
        assert "name: smoke" in (png.parent / "config.yaml").read_text(), png
        check_provenance(png.with_name(f"{png.stem}.provenance.json"))


def check_provenance(path: Path) -> None:
    prov = json.loads(path.read_text())
    assert prov["command"] and prov["finished"] >= prov["started"], path
    assert prov["efish_version"] == efish.__version__, path
    assert "scale=smoke" in prov["overrides"], path


@pytest.mark.slow
def test_the_recorded_command_reproduces_an_assay(smoke_run, tmp_path):
    """The provenance's command, rerun elsewhere, gives the same config and the same tables."""
    folder = smoke_run / "results/smoke/assays/patchy4"
    command = json.loads((folder / "provenance.json").read_text())["command"]
    args = command[1:]
    out = args.index("--out")
    args[out + 1] = str(tmp_path / "again")
    policy = args.index("--policy")
    name, path = args[policy + 1].split("=", 1)
    args[policy + 1] = f"{name}={smoke_run / path}"
    result = subprocess.run(["efish", *args], capture_output=True, text=True, timeout=300, env=smoke_env(smoke_run))
    assert result.returncode == 0, result.stderr
    assert (tmp_path / "again/config.yaml").read_text() == (folder / "config.yaml").read_text()
    for name in ("steps", "episodes", "food"):
        pd.testing.assert_frame_equal(pd.read_parquet(tmp_path / f"again/{name}.parquet"),
                                      pd.read_parquet(folder / f"{name}.parquet"))


def test_overrides_reach_every_efish_call(tmp_path):
    result = dry_run(tmp_path, "--config", "scale=smoke", "overrides=physics.tolerance=1e-6 train.lr=1e-3",
                     "--printshellcmds")
    assert result.returncode == 0, result.stderr[-2000:]
    calls = [line for line in result.stdout.splitlines() if line.startswith("Shell command: efish ")]
    assert len(calls) >= 8 and all("physics.tolerance=1e-6 train.lr=1e-3" in call for call in calls)


@pytest.mark.parametrize("config, target, message", [
    (["overrides=physics.tolerance=-1"], [], "efish config: physics.tolerance=-1.0 is out of range"),
    (["overrides=physics.nonsense=1"], [], "efish config: unknown config key 'physics.nonsense'"),
    (["overrides=scale.assays=[nope]"], [], "unknown assay 'nope'"),
    (["overrides=scale.keep_stages=[]"], ["learning"], "the learning target needs scale.keep_stages"),
    (["overrides=scale.learning=true scale.keep_stages=[]"], [], "learning=true needs scale.keep_stages"),
    (["overrides=scale.homing_seeds=2"], [], "efish workflow: scale.homing_seeds=2 exceeds scale.top_seeds=1"),
    (["overrides=scale.homing_seeds=0"], [], "efish config: scale.homing_seeds=0 is out of range"),
])
def test_bad_input_fails_before_any_job(tmp_path, config, target, message):
    result = dry_run(tmp_path, *target, "--config", "scale=smoke", *config)
    assert result.returncode != 0
    assert message in result.stdout + result.stderr
    assert not (tmp_path / "results").exists()


def dry_run(work: Path, *args: str) -> subprocess.CompletedProcess:
    return subprocess.run(["snakemake", "-n", "--cores", "1", "--snakefile", str(REPO / "Snakefile"),
                           "--directory", str(work), *args], capture_output=True, text=True, timeout=300)


def job_counts(dry_run_output: str) -> dict[str, int]:
    """Rule -> jobs, from the "Job stats" table Snakemake prints before a (dry) run."""
    table = dry_run_output.split("Job stats:", 1)[1].split("\n\n", 1)[0]
    rows = (line.split() for line in table.splitlines()[3:])
    return {row[0]: int(row[1]) for row in rows if len(row) == 2 and row[0] != "total"}


def test_one_job_draws_each_figure(tmp_path):
    """Every panel of a figure and its page come from one job; the drawing jobs are one per figure page plus the
    contact sheet (the benchmark figures are drawn by the jobs that measure them)."""
    from efish.config import compose
    from efish.figures.registry import drawable

    result = dry_run(tmp_path, "--config", "scale=smoke")
    assert result.returncode == 0, result.stderr[-2000:]
    jobs = job_counts(result.stdout)
    pages = {p.figure for p in drawable(compose(["scale=smoke"]).scale)}
    drawing = {rule: n for rule, n in jobs.items() if rule.startswith(("figure", "panel", "contact_sheet"))}
    assert drawing == {**{f"figure_{page}": 1 for page in pages}, "contact_sheet": 1}


#: The claims' verdicts, and how seeds_agree counts them ("2/2 hold", "1/2 hold, 1/2 absent (seed 1: ...)").
VERDICTS = {"holds", "absent", "opposite", "inconclusive", "not decidable", "not run"}
COUNT = r"\d+/\d+ (hold|absent|opposite|inconclusive|not decidable)"
SEEDS_AGREE = re.compile(rf"not run \(0/\d+ seeds ran\)|{COUNT}(, {COUNT})*"
                         r"( \((other seeds|seeds? [\d, ]+): not run\))?")


def selected(work: Path, seeds: list[int], ranking: list[int], run: str) -> None:
    """The select_seed checkpoint done in ``work``'s results/<run>: every seed trained and evaluated (empty files, in
    time order) and ranked ``ranking``, the first selected."""
    folder = work / "results" / run
    old, older = time.time() - 3600, time.time() - 7200
    for seed in seeds:
        for path, when in ((f"train/seed_{seed}/final.pt", older), (f"train/seed_{seed}/metrics.parquet", older),
                           *((f"selection/seed_{seed}/{t}.parquet", old) for t in ("episodes", "steps", "food", "conditions"))):
            (folder / path).parent.mkdir(parents=True, exist_ok=True)
            (folder / path).touch()
            os.utime(folder / path, (when, when))
    (folder / "analysis/selection").mkdir(parents=True)
    pd.DataFrame({"seed": ranking}).to_parquet(folder / "analysis/selection/ranking.parquet")
    (folder / "analysis/selection/selected_seed.txt").write_text(f"{ranking[0]}\n")


def test_the_other_top_seeds_rerun_the_claims_assays_for_their_own_claims(tmp_path):
    """With the select_seed checkpoint done (seed 2 chosen, seed 1 next), the smoke DAG with top_seeds 2 reruns every
    claim's assay that acts with the selected policy for seed 1, never homing (recipe policies), never the selected
    seed's, and the claims job combines seed 1's claims table with the selected seed's. The supplement's assays run
    both seeds in one job (efish assay --group); each seed's tables reach its copy of the layout by hard links."""
    # the smoke scale ships top_seeds 1 (CI time); run=smoke keeps the folder name with the override
    selected(tmp_path, [1, 2], [2, 1], "smoke")
    result = dry_run(tmp_path, "--config", "scale=smoke", "run=smoke", "overrides=scale.top_seeds=2",
                     "--rerun-triggers", "mtime", "--printshellcmds")
    assert result.returncode == 0, result.stderr[-2000:]
    out = result.stdout
    assert ("efish assay scale=smoke scale.top_seeds=2 assay=uniform4 --group 1=results/smoke/train/seed_1/final.pt "
            "--out 'results/smoke/seeds/groups/uniform4/seed_{member}'") in out
    assert ("efish assay scale=smoke scale.top_seeds=2 assay=patchy4 --group 2=results/smoke/train/seed_2/final.pt "
            "1=results/smoke/train/seed_1/final.pt --out 'results/smoke/seeds/groups/patchy4/seed_{member}'") in out
    assert ("ln -fv results/smoke/seeds/groups/uniform4/seed_1/* results/smoke/seeds/seed_1/assays/uniform4 "
            in out)
    assert "results/smoke/seeds/seed_1/assays/wide2/hidden.parquet" in out  # record_hidden: dynamics reads it
    assert ("--tables results/smoke/seeds/seed_1/assays/wide2 --out results/smoke/seeds/seed_1/analysis/dynamics/wide2"
            in out)
    assert "seeds/seed_1/assays/homing" not in out and "seeds/seed_2/assays/uniform4" not in out
    assert "seeds/groups/homing" not in out
    assert "seeds/seed_2/claims" not in out  # the selected seed's claims are the run's own
    assert ("efish claims scale=smoke scale.top_seeds=2 --results results/smoke/seeds/seed_1 --out "
            "results/smoke/seeds/seed_1/claims" in out)
    assert "results/smoke/seeds/seed_1/claims/claim_parts.parquet" in out  # the recipe's verdict reads seed 1's parts
    assert ("efish claims scale=smoke scale.top_seeds=2 --results results/smoke --out results/smoke/claims --ranking "
            "results/smoke/analysis/selection/ranking.parquet --seed-claims "
            "1=results/smoke/seeds/seed_1/claims/claims.parquet") in out


def test_one_job_rolls_out_every_top_seed_that_reruns_an_assay(tmp_path):
    """The laptop scale's 4 top seeds rerun 12 assays: the 9 claim assays that are not the supplement's, each by the
    3 other seeds, and the supplement's 3, each by all 4 (39 table sets). Each assay's reruns are one efish call
    (top_seed_group: 12 calls, each paying the start-up once, where there were 39 jobs); each seed's tables reach its
    copy of the layout by one job that starts no Python (top_seed_assay*: 39 hard links; a local rule, which a
    cluster does not queue)."""
    from efish.config import compose

    selected(tmp_path, compose(["scale=laptop"]).scale.seed_numbers(), [3, 1, 4, 2], "laptop")
    result = dry_run(tmp_path, "--config", "scale=laptop", "--rerun-triggers", "mtime", "--printshellcmds")
    assert result.returncode == 0, result.stderr[-2000:]
    jobs = job_counts(result.stdout)
    assert jobs["top_seed_group"] == 12 and jobs["top_seed_assay"] + jobs["top_seed_assay_with_hidden"] == 39
    calls = [line for line in result.stdout.splitlines() if line.startswith("Shell command: efish assay")
             and "/seeds/" in line]
    grouped = [call for call in calls if " --group " in call]
    assert len(grouped) == 12 and all(" --group 3=" in call or " --group 1=" in call for call in grouped)
    # homing, acted by two recipes, is rerun solo by the 2nd and 3rd top seeds (scale.homing_seeds: the test below)
    assert [" assay=homing " in call for call in calls if call not in grouped] == [True, True]
    assert len(re.findall(r"^Shell command: \(ln -fv results/laptop/seeds/groups/", result.stdout, flags=re.M)) == 39


#: The jobs scale.homing_seeds = 3 (the laptop scale's) adds to one draw of the homing recipes: both recipes trained
#: again for draws 2 and 3, and the 2nd and 3rd top seeds' homing (which records hidden states), each with the two
#: analyses the homing claims read (homing's and dynamics').
DRAW_JOBS = {"train_policy": 4, "top_seed_recipe_assay_with_hidden": 2, "top_seed_analysis_homing": 2,
             "top_seed_analysis_dynamics": 2}


def test_the_top_seeds_rerun_homing_each_with_its_own_draw_of_the_homing_recipes(tmp_path):
    """The laptop scale decides the homing claims over scale.homing_seeds = 3 draws of the homing recipes: draw k
    >= 2 trains homing and homing_raycast again with train.seed k into train/<recipe>_draw_<k>/, and the k-th top
    seed (ranking 3, 1, 4, 2: seed 1 draw 2, seed 4 draw 3) reruns homing alone with draw k's policies, then the
    analyses its claims read. Seed 2, fourth, reruns no homing. With homing_seeds=1 the DAG is the one before."""
    from efish.config import compose

    seeds = compose(["scale=laptop"]).scale.seed_numbers()
    runs = {}
    for name, config in (("three", []), ("one", ["overrides=scale.homing_seeds=1"])):
        selected(tmp_path / name, seeds, [3, 1, 4, 2], "laptop")
        result = dry_run(tmp_path / name, "--config", "scale=laptop", "run=laptop", *config, "--rerun-triggers",
                         "mtime", "--printshellcmds")
        assert result.returncode == 0, result.stderr[-2000:]
        runs[name] = result.stdout
    three, one = job_counts(runs["three"]), job_counts(runs["one"])
    assert {rule: n - one.get(rule, 0) for rule, n in three.items() if n != one.get(rule, 0)} == DRAW_JOBS
    assert one["train_policy"] == 2 and "top_seed_recipe_assay_with_hidden" not in one
    assert "_draw_" not in runs["one"] and not re.search(r"seeds/seed_\d+/assays/homing", runs["one"])
    out = runs["three"]
    for k in (2, 3):
        for recipe in ("homing", "homing_raycast"):
            assert (f"efish train scale=laptop train.seed={k} policy={recipe} train.threads=1 --out "
                    f"results/laptop/train/{recipe}_draw_{k} ") in out
    assert "efish train scale=laptop policy=homing train.threads=1 --out results/laptop/train/homing " in out
    for seed, k in ((1, 2), (4, 3)):
        assert (f"efish assay scale=laptop scale.max_episodes=6 assay=homing --policy "
                f"homing=results/laptop/train/homing_draw_{k}/final.pt "
                f"homing_raycast=results/laptop/train/homing_raycast_draw_{k}/final.pt "
                f"--out results/laptop/seeds/seed_{seed}/assays/homing ") in out
        for analysis in ("homing", "dynamics"):
            assert (f"efish analyze {analysis} scale=laptop assay=homing --tables "
                    f"results/laptop/seeds/seed_{seed}/assays/homing --out "
                    f"results/laptop/seeds/seed_{seed}/analysis/{analysis}/homing ") in out
    assert "seeds/seed_2/assays/homing" not in out and "seeds/seed_3/assays/homing" not in out
    assert "seeds/groups/homing" not in out  # never a group: two policies per seed
    # the 2nd top seed's claims read its homing tables; the 4th's do not
    claims = {m.group(1): m.group(0) for m in re.finditer(r"^rule top_seed_claims:\n    input: .*seed_(\d)/.*$", out,
                                                          flags=re.M)}
    assert "seeds/seed_1/analysis/homing/homing/trajectory_shape.parquet" in claims["1"]
    assert "analysis/homing/homing" not in claims["2"]


@pytest.mark.slow
def test_the_second_top_seed_decides_the_homing_claims_with_its_own_draw_of_the_recipes(smoke_run, tmp_path):
    """The smoke run's seeds and selection, with scale.top_seeds=2 scale.homing_seeds=2: both homing recipes train
    again with train.seed 2, the second top seed reruns homing with them and runs the analyses the homing claims
    read, and its claims carry the homing claims' parts from its own tables (C18's effect is finite; C1-C3 need
    successful homing episodes, which nothing trained at this scale has). Only the homing tables are made: the
    other claims' reruns are the grouped reruns' test."""
    from efish.layout import CLAIM_PARTS, RANKING, assay_table, recipe_draw, training_file
    from efish.run_plan import RunPlan

    work = scratch_workflow(tmp_path / "work")
    for part in ("train", "selection", "analysis/selection"):  # the checkpoint done, in time order (copy2: mtimes)
        shutil.copytree(smoke_run / "results/smoke" / part, work / "results/smoke" / part)
    overrides = "scale.top_seeds=2 scale.homing_seeds=2"
    run = Run("smoke", results_root=work / "results")
    second = int(pd.read_parquet(run.path(RANKING))["seed"].iloc[1])
    copy = Run("smoke").top_seed(second)  # its tables as Snakemake names them, relative to the work folder
    tables = RunPlan.from_config({"scale": "smoke", "overrides": overrides}).claims_read(["homing"])
    result = subprocess.run(["snakemake", "--cores", "1", "--config", "scale=smoke", "run=smoke",
                             f"overrides={overrides}", "--rerun-triggers", "mtime", "--directory", str(work),
                             "--snakefile", str(work / "Snakefile"), *[str(copy.path(t)) for t in tables]],
                            capture_output=True, text=True, timeout=900, env=smoke_env(work))
    assert result.returncode == 0, result.stderr[-3000:]
    for recipe in ("homing", "homing_raycast"):
        config = run.path(training_file(recipe_draw(recipe, 2), "config.yaml")).read_text()
        assert re.search(r"^  seed: 2$", config, flags=re.M), recipe
    homing = run.top_seed(second).path(assay_table("homing", "episodes")).parent
    recorded = json.loads((homing / "provenance.json").read_text())["command"]
    assert "homing=results/smoke/train/homing_draw_2/final.pt" in recorded
    assert "homing_raycast=results/smoke/train/homing_raycast_draw_2/final.pt" in recorded
    out = tmp_path / "claims"
    claims = subprocess.run(["efish", "claims", "scale=smoke", "scale.top_seeds=2", "scale.homing_seeds=2",
                             "--results", str(run.top_seed(second).results), "--out", str(out)],
                            capture_output=True, text=True, timeout=300, env=smoke_env(work))
    assert claims.returncode == 0, claims.stderr[-2000:]
    parts = pd.read_parquet(out / Path(CLAIM_PARTS).name)
    homing_parts = parts[parts["claim"].isin(["C1", "C2", "C3", "C18"])]
    assert set(homing_parts["claim"]) == {"C1", "C2", "C3", "C18"}
    assert not homing_parts["reason"].str.startswith("needs ").any(), homing_parts["reason"].tolist()
    assert homing_parts.loc[homing_parts["claim"] == "C18", "effect"].map(np.isfinite).all()


@pytest.mark.slow
def test_a_grouped_rerun_gives_each_seed_the_tables_of_its_run_alone(smoke_run, tmp_path):
    """Both smoke seeds as top seeds: one job rolls out both in patchy4 and in wide2 (which records hidden states),
    and each seed's tables in its copy of the layout are, byte for byte, those of efish assay run with that seed
    alone; the group's folder is gone once every seed has its tables."""
    work = scratch_workflow(tmp_path / "grouped")
    for part in ("train", "selection", "analysis/selection"):  # the checkpoint done, in time order (copy2: mtimes)
        shutil.copytree(smoke_run / "results/smoke" / part, work / "results/smoke" / part)
    overrides = ["scale=smoke", "scale.top_seeds=2"]
    tables = {"patchy4": ["steps", "episodes", "food", "conditions"], "wide2": ["steps", "hidden"]}
    targets = [f"results/smoke/seeds/seed_{seed}/assays/{assay}/{t}.parquet" for seed in (1, 2)
               for assay, names in tables.items() for t in names]
    result = subprocess.run(["snakemake", "--cores", "1", "--config", "scale=smoke", "run=smoke",
                             f"overrides={overrides[1]}", "--rerun-triggers", "mtime", "--directory", str(work),
                             "--snakefile", str(work / "Snakefile"), *targets],
                            capture_output=True, text=True, timeout=900, env=smoke_env(work))
    assert result.returncode == 0, result.stderr[-3000:]
    assert re.findall(r"^(?:local)?rule (\w+):", result.stderr, flags=re.M).count("top_seed_group") == 2
    assert not (work / "results/smoke/seeds/groups/patchy4").exists()  # temp: removed once both seeds have theirs
    for seed in (1, 2):
        for assay, names in tables.items():
            alone = tmp_path / f"alone_{seed}_{assay}"
            solo = subprocess.run(["efish", "assay", *overrides, f"assay={assay}", "--policy",
                                   f"selected={work}/results/smoke/train/seed_{seed}/final.pt", "--out", str(alone)],
                                  capture_output=True, text=True, timeout=300, env=smoke_env(work))
            assert solo.returncode == 0, solo.stderr[-2000:]
            grouped = work / f"results/smoke/seeds/seed_{seed}/assays/{assay}"
            for name in [*names, "config"]:
                suffix = ".yaml" if name == "config" else ".parquet"
                assert (grouped / f"{name}{suffix}").read_bytes() == (alone / f"{name}{suffix}").read_bytes(), \
                    (seed, assay, name)
            assert "--group" in json.loads((grouped / "provenance.json").read_text())["command"]


@pytest.mark.slow
def test_the_claims_carry_the_verdicts_of_the_top_seeds(smoke_run):
    """The smoke DAG's claims table has seed_verdicts and seeds_agree and only the claims' verdicts (the smoke
    scale runs top_seeds 1; the other seeds' reruns are the dry run above and tests/analysis/test_claims_seeds.py)."""
    run = smoke_run / "results/smoke"
    claims = pd.read_parquet(run / "claims/claims.parquet")
    assert {"seed_verdicts", "seeds_agree"} <= set(claims.columns) and set(claims["verdict"]) <= VERDICTS
    assert all(SEEDS_AGREE.fullmatch(v) for v in claims["seeds_agree"]), claims["seeds_agree"].tolist()
    selected = int(pd.read_parquet(run / "analysis/selection/ranking.parquet")["seed"].iloc[0])
    assert all(v == f"seed {selected}: {verdict}" for v, verdict in zip(claims["seed_verdicts"], claims["verdict"],
                                                                          strict=True))
    assert not (run / "seeds" / f"seed_{selected}" / "claims").exists()  # the selected seed's are the run's own
    assert "| seeds_agree |" in (run / "claims/claims.md").read_text()
    # one seed: the recipe's verdict (a test over seeds) is there, never decided, and its parts say why
    assert claims["recipe_verdict"].isin(["not run", "not decidable"]).all() and (claims["recipe_seeds"] <= 1).all()
    recipe = pd.read_parquet(run / "claims/recipe_parts.parquet")
    assert list(recipe.columns) == RECIPE_PART_COLUMNS and recipe["verdict"].isin(["not run", "not decidable"]).all()


@pytest.mark.slow
def test_accuracy_table_matches_its_schema(smoke_run):
    df = pd.read_parquet(smoke_run / "results/smoke/bench/bench_accuracy.parquet")
    assert list(df.columns) == list(COLUMNS)
    assert df["is_default"].sum() == 1
    exact = df[(df.tolerance == 0) & (df.image_order == 3) & (df.dtype == "float64") & (df.softening_m == 1e-5)]
    assert (exact["max_abs_error"] == 0).all()  # the reference itself
    assert (df["us_per_agent_step"] > 0).all()


@pytest.mark.slow
def test_physics_bench_reports_its_numbers(smoke_run):
    r = json.loads((smoke_run / "results/smoke/bench/bench_physics.json").read_text())
    assert r["fast_agent_steps_per_s"] > 0 and r["reference_agent_steps_per_s"] > 0
    assert r["max_abs_diff_normalised"] <= 1e-6


@pytest.mark.slow
def test_scale_is_recorded_in_the_resolved_config(smoke_run):
    assert "name: smoke" in (smoke_run / "results/smoke/bench/config.yaml").read_text()


def test_unknown_scale_fails_before_any_job(tmp_path):
    result = dry_run(tmp_path, "--config", "scale=huge")
    assert result.returncode != 0
    assert result.stderr.strip().splitlines()[-1].startswith("efish workflow: efish config: unknown scale 'huge'")


def test_a_misspelt_config_key_is_one_line_naming_the_allowed_ones(tmp_path):
    result = dry_run(tmp_path, "--config", "scal=smoke")
    assert result.returncode != 0
    assert result.stderr.strip() == ("efish workflow: unknown --config key(s) scal: the allowed keys are scale, "
                                     "overrides, run, sweep")
    assert not (tmp_path / "results").exists()


def test_overrides_and_run_names_give_their_own_folders(tmp_path):
    for config, folder in ((["scale=smoke"], "smoke"),
                           (["scale=smoke", "overrides=train.lr=3e-4"], run_name("smoke", ["train.lr=3e-4"])),
                           (["scale=smoke", "overrides=train.lr=3e-4", "run=mine"], "mine")):
        result = dry_run(tmp_path, "--config", *config)
        assert result.returncode == 0, result.stderr[-2000:]
        assert f"results/{folder}/train/seed_1/final.pt" in result.stdout
        assert f"figures/{folder}/bench/bench_accuracy.pdf" in result.stdout


@pytest.mark.slow
def test_a_sweep_plans_a_run_per_point_and_trains_each_seed_once(tmp_path):
    """Points that differ in scale.max_episodes train alike: the first point trains each seed and policy, the
    second gets copies of all of them (share_train, share_train_policy), and each point runs its own assays,
    analyses and claims in the folder a single run of its overrides gets."""
    from efish.config import compose

    result = dry_run(tmp_path, "--config", "scale=smoke", "sweep=scale.max_episodes=2,3")
    assert result.returncode == 0, result.stderr[-2000:]
    jobs = job_counts(result.stdout)
    seeds = len(compose(["scale=smoke"]).scale.seed_numbers())
    assert jobs["train"] == jobs["share_train"] == seeds and jobs["train_policy"] == jobs["share_train_policy"]
    assert {rule for rule in jobs if rule.startswith("share_")} == {"share_train", "share_train_policy"}
    assert jobs["evaluate_seed"] == 2 * seeds and jobs["claims"] == 2 and jobs["bench_physics"] == 2
    other = run_name("smoke", ["scale.max_episodes=3"])
    assert f"results/{other}/claims/claims.parquet" in result.stdout
    assert f"results/{other}/train/seed_1/final.pt" in result.stdout


@pytest.mark.slow
def test_a_sweep_over_an_analysis_key_runs_only_the_analyses_claims_and_figures_again(tmp_path):
    """Points alike but for analysis.claims_alpha: the second copies the first's training, seed selection episodes,
    assays, scenes, benchmarks and clips; the first, at the scale's own value, is the plain smoke run."""
    result = dry_run(tmp_path, "--config", "scale=smoke", "sweep=analysis.claims_alpha=0.05,0.01")
    assert result.returncode == 0, result.stderr[-2000:]
    jobs = job_counts(result.stdout)
    for rule in ("train", "train_policy", "evaluate_seed", "assay", "assay_with_hidden", "scene", "bench_physics",
                 "render_clip"):
        assert jobs[rule] == jobs[f"share_{rule}"], rule  # run once, copied once
    assert jobs["select_seed"] == jobs["claims"] == jobs["contact_sheet"] == 2
    assert "results/smoke/claims/claims.parquet" in result.stdout
    assert f"results/{run_name('smoke', ['analysis.claims_alpha=0.01'])}/claims/claims.parquet" in result.stdout


@pytest.mark.parametrize("config, message", [
    (["sweep=train.lr"], "efish workflow: sweep: 'train.lr' is not KEY=VALUE,VALUE,..."),
    (["sweep=train.lr=1e-3,3e-4", "run=mine"], "efish workflow: run= names one folder and a sweep makes one per "
                                               "point"),
])
def test_a_bad_sweep_fails_before_any_job_in_one_line(tmp_path, config, message):
    result = dry_run(tmp_path, "--config", "scale=smoke", *config)
    assert result.returncode != 0
    assert result.stderr.strip().startswith(message) and len(result.stderr.strip().splitlines()) == 1
    assert not (tmp_path / "results").exists()


def test_workflow_lints_clean():
    result = subprocess.run(["snakemake", "--lint", "--snakefile", str(REPO / "Snakefile")], capture_output=True,
                            text=True, cwd=REPO)
    assert "Congratulations, your workflow is in a good condition" in result.stdout + result.stderr


@pytest.mark.slow
def test_a_killed_training_job_resumes_from_its_checkpoint(tmp_path):
    """Interrupt the pipeline mid-training; the rerun continues the seed from its last checkpoint."""
    for name in ("Snakefile", "workflow", "config"):
        src = REPO / name
        (shutil.copytree if src.is_dir() else shutil.copy)(src, tmp_path / name)
    seed_dir = tmp_path / "results/kill/train/seed_1"
    command = ["snakemake", "results/kill/train/seed_1/final.pt", "--cores", "1", "--rerun-incomplete",
               "--directory", str(tmp_path), "--snakefile", str(tmp_path / "Snakefile"), "--config", "scale=smoke",
               "overrides=scale.train_steps=30000 train.checkpoint_every=1", "run=kill"]
    # a shell that starts pytest in the background sets SIGINT to ignored, and children inherit that: restore it
    first = subprocess.Popen(command, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, start_new_session=True,
                             env=smoke_env(tmp_path), preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_DFL))
    deadline = time.monotonic() + 240
    while not (seed_dir / "checkpoint.pt").exists() and time.monotonic() < deadline and first.poll() is None:
        time.sleep(0.2)
    time.sleep(1.0)
    os.killpg(first.pid, signal.SIGINT)  # what Ctrl-C does
    first.wait(timeout=120)
    assert (seed_dir / "checkpoint.pt").exists() and not (seed_dir / "final.pt").exists()

    second = subprocess.run(command, capture_output=True, text=True, timeout=600, env=smoke_env(tmp_path))
    assert second.returncode == 0, second.stderr[-2000:]
    log = (tmp_path / "results/kill/logs/train/seed_1.log").read_text()
    resumed = re.search(r"resumed from .* at update (\d+)", log)
    assert resumed and int(resumed.group(1)) >= 1, log[-2000:]
    metrics = pd.read_parquet(seed_dir / "metrics.parquet")
    assert list(metrics["update"]) == list(range(1, 301))  # 30000 steps of 100: nothing lost, nothing repeated


@pytest.mark.slow
def test_the_readme_override_example_reruns_cleanly_beside_the_default_run(smoke_run):
    """After a finished run, the override example runs in its own folder, twice, and the default stays as it was.
    It asks for one assay's tables (training, selection and the assay: every kind of job an override reaches
    before the analyses); test_a_run_override_reaches_every_drawing carries overrides on to the figures."""
    before = {p: p.stat().st_mtime_ns for p in (smoke_run / "results/smoke").glob("**/*") if p.is_file()}
    folder = run_name("smoke", ["physics.tolerance=1e-6", "train.lr=3e-4"])
    command = ["snakemake", "--cores", "2", "--config", "scale=smoke",
               "overrides=physics.tolerance=1e-6 train.lr=3e-4", "--directory", str(smoke_run),
               "--snakefile", str(smoke_run / "Snakefile"), f"results/{folder}/assays/patchy4/steps.parquet"]
    for attempt in range(2):
        result = subprocess.run(command, capture_output=True, text=True, timeout=900, env=smoke_env(smoke_run))
        assert result.returncode == 0, (attempt, result.stderr[-3000:])
    run = smoke_run / "results" / folder
    assert "tolerance: 1.0e-06" in (run / "train/seed_1/config.yaml").read_text()
    assert "Nothing to be done" in result.stdout + result.stderr  # the second attempt reuses the first's outputs
    after = {p: p.stat().st_mtime_ns for p in (smoke_run / "results/smoke").glob("**/*") if p.is_file()}
    assert after == before


@pytest.mark.parametrize("conditions, message", [
    ('{control: ["env.nonsense=1"]}', "condition control: unknown config key 'env.nonsense'"),
    ('{rays: ["sensors.perception=raycast"]}', "condition rays: its observation has 83 values but policy 'selected'"),
    ('{other: ["assay.policy=nope"]}', "asks for policies nope"),
])
def test_a_bad_assay_condition_stops_before_any_job_in_one_line(tmp_path, conditions, message):
    shutil.copytree(REPO / "config", tmp_path / "config")
    (tmp_path / "config/assay/bad.yaml").write_text(
        "# @package _global_\nassay:\n  name: bad\n  conditions: " + conditions + "\n")
    result = subprocess.run(["snakemake", "-n", "--cores", "1", "--snakefile", str(REPO / "Snakefile"),
                             "--directory", str(tmp_path), "--config", "scale=smoke", "overrides=scale.assays=[bad]"],
                            capture_output=True, text=True, timeout=300, env=smoke_env(tmp_path))
    assert result.returncode != 0
    last = result.stderr.strip().splitlines()[-1]
    assert last.startswith("efish workflow: assay bad") and message in last, result.stderr[-2000:]
    assert not (tmp_path / "results").exists()


def test_a_new_assay_file_is_built_when_asked_for_without_joining_the_default_target(tmp_path):
    """One YAML file in config/assay/ asks a new question: its tables are a target at once, with the selected
    seed, while the default target stays the scale's assays."""
    shutil.copytree(REPO / "config", tmp_path / "config")
    (tmp_path / "config/assay/dark.yaml").write_text(
        "# @package _global_\nassay:\n  name: dark\n  conditions: {control: [], dark: [\"env.muted=[0,1,2,3]\"]}\n")
    base = ["snakemake", "-n", "--cores", "1", "--snakefile", str(REPO / "Snakefile"), "--directory", str(tmp_path)]
    asked = subprocess.run([*base, "results/smoke/assays/dark/steps.parquet", "--config", "scale=smoke"],
                           capture_output=True, text=True, timeout=300, env=smoke_env(tmp_path))
    assert asked.returncode == 0, asked.stderr[-2000:]
    assert re.search(r"^assay\s+1$", asked.stdout, re.M) and "assays/dark/steps.parquet" in asked.stdout
    default = subprocess.run([*base, "--config", "scale=smoke"], capture_output=True, text=True, timeout=300,
                             env=smoke_env(tmp_path))
    assert default.returncode == 0 and "assays/dark/" not in default.stdout, default.stderr[-2000:]


def test_a_bad_assay_file_outside_the_scale_stops_every_run_in_one_line(tmp_path):
    shutil.copytree(REPO / "config", tmp_path / "config")
    (tmp_path / "config/assay/draft.yaml").write_text(
        "# @package _global_\nassay:\n  name: draft\n  conditions: {control: [\"env.nonsense=1\"]}\n")
    result = subprocess.run(["snakemake", "-n", "--cores", "1", "--snakefile", str(REPO / "Snakefile"),
                             "--directory", str(tmp_path), "--config", "scale=smoke"],
                            capture_output=True, text=True, timeout=300, env=smoke_env(tmp_path))
    last = result.stderr.strip().splitlines()[-1]
    assert result.returncode != 0 and last.startswith("efish workflow: assay draft"), result.stderr[-2000:]
    assert "unknown config key 'env.nonsense'" in last


@pytest.mark.slow
def test_a_run_override_reaches_every_drawing(smoke_run, tmp_path):
    """env.fps on the command line and other one-patch sizes in the assay file: Fig 3's EOD-rate axis (Hz) and
    Fig 5's size classes follow what the run recorded (conditions.parquet), not the config files, which the
    drawings here read with the repository's own (default fps, default sizes). The smoke run's trained seeds are
    reused (copied with their times, --rerun-triggers mtime) so that only the assays and what follows run."""
    from efish.figures.fig5 import matched_alone
    from efish.figures.registry import PANELS
    from efish.figures.render import load_tables
    from efish.figures.style import assay_conditions

    from ..helpers import draw_panel_axes, scratch_workflow

    work = scratch_workflow(tmp_path / "work")
    onepatch = work / "config/assay/onepatch.yaml"
    text = onepatch.read_text()
    assert 'A_lt_B: ["env.sizes=[0.25,0.75]"]' in text
    onepatch.write_text(text.replace('A_lt_B: ["env.sizes=[0.25,0.75]"]', 'A_lt_B: ["env.sizes=[0.5,0.75]"]'))
    run = work / "results/fps"
    for part in ("train", "selection", "analysis/selection"):
        shutil.copytree(smoke_run / "results/smoke" / part, run / part)
    command = ["snakemake", "--cores", "2", "--config", "scale=smoke", "overrides=env.fps=50", "run=fps",
               "--rerun-triggers", "mtime", "--directory", str(work), "--snakefile", str(work / "Snakefile"),
               "figures/fps/fig3.png", "figures/fps/fig5.png"]
    result = subprocess.run(command, capture_output=True, text=True, timeout=1200, env=smoke_env(work))
    assert result.returncode == 0, result.stderr[-3000:]
    assert "rule train" not in result.stdout + result.stderr  # the copied seeds were reused

    recorded = pd.read_parquet(run / "assays/patchy4/conditions.parquet")
    assert (recorded["fps"] == 50).all()
    tables = load_tables(PANELS["fig3/O"], run, seeds=2)
    ax = draw_panel_axes("fig3/O", tables)
    plotted = sorted(float(y) for c in ax.collections for _, y in c.get_offsets())
    expected = sorted(tables["eod_probability"].dropna(subset=["size", "eod_probability"])["eod_probability"] * 50)
    assert plotted and plotted == pytest.approx(expected)

    configs = assay_conditions(load_tables(PANELS["fig5/E"], run, seeds=2), "onepatch")
    assert configs["A_lt_B"].env.sizes == [0.5, 0.75] and configs["A_lt_B"].env.fps == 50
    assert matched_alone(configs)["A", "A_lt_B"] == "A_alone_50"  # the files here would say A_alone_25


@pytest.mark.slow
def test_the_learning_target_runs_the_claims_at_each_kept_stage(smoke_run, tmp_path):
    """`snakemake learning` at smoke scale (scale.keep_stages [0.5, 1.0]): the selected seed's stage_1.pt acts in
    every claim's assay in learning/stage_1/ (at most scale.stage_episodes episodes per condition), its analyses
    and claims follow, and the last stage (fraction 1) is the run's own claims; claims_by_stage stacks both. The
    smoke run's results are copied with their times so that only the stage's jobs run."""
    from ..helpers import scratch_workflow

    work = scratch_workflow(tmp_path / "work")
    shutil.copytree(smoke_run / "results/smoke", work / "results/smoke")
    selected = int((work / "results/smoke/analysis/selection/selected_seed.txt").read_text())
    command = ["snakemake", "--cores", "2", "--config", "scale=smoke", "--rerun-triggers", "mtime", "--printshellcmds",
               "--directory", str(work), "--snakefile", str(work / "Snakefile"), "learning"]
    result = subprocess.run(command, capture_output=True, text=True, timeout=1200, env=smoke_env(work))
    assert result.returncode == 0, result.stderr[-3000:]
    log = result.stdout + result.stderr
    assert "rule train:" not in log and "rule assay:" not in log and "rule claims:" not in log  # the run's own
    assert f"--policy selected=results/smoke/train/seed_{selected}/stage_1.pt" in log
    assert "scale.max_episodes=2" in log

    learning = work / "results/smoke/learning"
    stage = pd.read_parquet(learning / "stage_1/assays/patchy4/conditions.parquet")
    assert (stage["episodes"] <= 2).all()
    stacked = pd.read_parquet(learning / "claims_by_stage.parquet")
    steps = stacked.groupby("stage")["env_steps"].first()
    assert list(steps.index) == [1, 2] and steps.is_monotonic_increasing
    own = pd.read_parquet(work / "results/smoke/claims/claim_parts.parquet")
    last = stacked[stacked["stage"] == 2]
    assert len(last) == len(own) and set(last["claim"]) == set(own["claim"])
    assert set(pd.read_parquet(learning / "claims_trends.parquet")["claim"]) <= set(stacked["claim"])
    assert "Along training" in (learning / "claims.md").read_text()
    for group in ("fig2", "fig3", "fig4", "fig5", "fig6"):
        for ext in ("png", "pdf"):
            assert (work / f"figures/smoke/learning/claims_by_stage_{group}.{ext}").stat().st_size > 0
