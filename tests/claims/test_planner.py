"""The planner reads a run's per-seed parts tables and benchmark files and plans each part over seeds."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest
from scipy import stats

from efish.claims.intervals import signed_rank_interval
from efish.claims.planner import (
    CURVE_COLUMNS,
    CURVE_SEEDS,
    MORE_EPISODES,
    PLAN_COLUMNS,
    RunCosts,
    claim_curves,
    part_models,
    plan_parts,
    plan_table,
    power_curves,
    run_costs,
)
from efish.claims.power import (
    SIGNED_RANK,
    decision_probabilities,
    own_decision_probabilities,
    own_standard_error,
    units_needed,
)
from efish.claims.power_page import power_markdown
from efish.cli import main
from efish.layout import (
    CLAIM_PARTS,
    CLAIMS_BY_STAGE,
    CLAIMS_TABLE,
    CLAIMS_TRENDS,
    RANKING,
    RECIPE_PARTS,
    Run,
    top_seed_group,
)

ALPHA = 0.05
#: The ci_method of a t interval over a seed's units (C4's, a t-test over episodes).
T_METHOD = f"inverts the clustered t-test, level {1 - 2 * ALPHA:.3g}"


def parts_table(rng, seed_effects: dict[str, float], tau: float, sigma: float, n: int, delta: float) -> pd.DataFrame:
    """One seed's claim_parts rows: each part's effect drawn around its true value (between-seed tau), its
    interval the t interval at 1 - 2 alpha of n units with SD sigma."""
    rows = []
    for part, true in seed_effects.items():
        data = rng.normal(rng.normal(true, tau), sigma, n)
        half = stats.t.ppf(1 - ALPHA, n - 1) * data.std(ddof=1) / np.sqrt(n)
        rows.append({"claim": "C9", "part": part, "sign": 1.0, "effect": data.mean(), "ci_low": data.mean() - half,
                     "ci_high": data.mean() + half, "ci_method": T_METHOD, "n": n, "family": 1, "delta": delta,
                     "verdict": "inconclusive"})
    return pd.DataFrame(rows)


COSTS = RunCosts(train_s=400.0, selection_s=20.0, rerun_s=180.0, seeds_timed="test")


def test_a_large_effect_needs_few_seeds_and_no_effect_settles_as_absent():
    rng = np.random.default_rng(4)
    tables = {s: parts_table(rng, {"large": 0.5, "none": 0.0}, tau=0.05, sigma=0.2, n=8, delta=0.1)
              for s in (3, 1, 4, 2)}
    table = plan_parts(tables, ALPHA, COSTS)
    assert list(table.columns) == PLAN_COLUMNS
    plan = table.set_index("part")
    assert set(plan.index) == {"large", "none"}
    assert (plan["seeds"] == 4).all() and (plan["units"] == 8).all()
    for part in ("large", "none"):
        row = plan.loc[part]
        k = int(row["seeds_holds_at_2delta"])
        assert row["cpu_hours_holds_at_2delta"] == pytest.approx(k * 600 / 3600)
        # the design it names reaches the target, and at its current seeds the chance is the one it reports
        sd = np.sqrt(row["tau"] ** 2 + row["sigma"] ** 2 / row["units"])
        assert decision_probabilities(0.2, sd, k, 1, 0.1, ALPHA)["holds"] >= 0.8
        assert row["now_holds_at_2delta"] == pytest.approx(decision_probabilities(0.2, sd, 4, 1, 0.1, ALPHA)["holds"])
    assert plan.loc["none", "effect"] == pytest.approx(np.mean([t.set_index("part").loc["none", "effect"]
                                                                for t in tables.values()]))


def test_a_part_one_seed_carries_is_not_planned_and_says_why():
    rng = np.random.default_rng(5)
    tables = {s: parts_table(rng, {"p": 0.3}, 0.05, 0.2, 8, 0.1) for s in (1, 2)}
    tables[2].loc[0, "verdict"] = "not run"
    row = plan_parts(tables, ALPHA, COSTS).iloc[0]
    assert row["seeds"] == 1 and np.isnan(row["seeds_holds_at_2delta"]) and "1 seed(s)" in row["note"]


def benchmark(path, cpu_time: float, wall: float = 1.0) -> None:
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(f"s\th:m:s\tmax_rss\tcpu_time\n{wall}\t0:00:01\t100\t{cpu_time}\n")


def test_run_costs_reads_the_runs_own_benchmarks(tmp_path):
    run = Run("r", results_root=tmp_path)
    for seed, cpu in ((1, 300.0), (2, 500.0)):
        benchmark(run.benchmark(f"train/seed_{seed}"), cpu)
        benchmark(run.benchmark(f"selection/seed_{seed}"), 10.0)
    benchmark(run.top_seed(2).benchmark("assays/patchy4"), 60.0)
    benchmark(run.top_seed(2).benchmark("claims"), 20.0)
    benchmark(run.benchmark("seeds/patchy4"), 999.0)  # the stacked table of all top seeds: not a seed's rerun
    costs = run_costs(run, [1, 2], other_top_seeds=1)
    assert (costs.train_s, costs.selection_s, costs.rerun_s) == (400.0, 10.0, 80.0)
    assert costs.run_s == 300 + 500 + 2 * 10 + 60 + 20 + 999  # every job of the run
    assert costs.design_hours(9) == pytest.approx(9 * 490 / 3600) and np.isnan(costs.design_hours(None))
    unpriced = run_costs(Run("empty", results_root=tmp_path), [1], 0)  # e.g. a sweep's point that copied its training
    assert np.isnan(unpriced.design_hours(3)) and "unpriced" in unpriced.seeds_timed


def test_curves_rise_with_seeds_and_a_claim_reads_its_weakest_part():
    rng = np.random.default_rng(6)
    tables = {s: parts_table(rng, {"large": 0.5, "small": 0.15}, tau=0.05, sigma=0.2, n=8, delta=0.1)
              for s in (3, 1, 4)}
    models = part_models(tables, ALPHA)
    curves = power_curves(models, ALPHA, COSTS, seeds=(2, 4, 8, 16))
    assert list(curves.columns) == CURVE_COLUMNS and len(curves) == 2 * 4
    for _, rows in curves.groupby("part"):
        assert (np.diff(rows["holds_at_2delta"]) >= -1e-9).all()  # more seeds, never less power
        assert rows["cpu_hours"].tolist() == pytest.approx([k * 600 / 3600 for k in (2, 4, 8, 16)])
    claim = claim_curves(curves)
    assert len(claim) == 4 and (claim["claim"] == "C9").all()
    weakest = curves.groupby("seeds")["holds_at_2delta"].min().to_numpy()
    assert claim["holds_at_2delta"].to_numpy() == pytest.approx(weakest)
    # the curve's value at the run's seeds is the plan's "now"
    plan = plan_table(models, ALPHA, COSTS).set_index("part")
    at3 = power_curves(models, ALPHA, COSTS, seeds=(3,)).set_index("part")
    assert at3["holds_at_2delta"].to_numpy() == pytest.approx(plan.loc[at3.index, "now_holds_at_2delta"].to_numpy())


def write_run(root, effects: dict[int, float]) -> Run:
    """A finished run's files as the planner reads them: the ranking, each top seed's claim_parts and the
    benchmark files of its training and selection."""
    run = Run("laptop", results_root=root)
    rng = np.random.default_rng(7)
    ranking = list(effects)
    run.path(RANKING).parent.mkdir(parents=True)
    pd.DataFrame({"seed": ranking}).to_parquet(run.path(RANKING))
    for i, seed in enumerate(ranking):
        where = run if i == 0 else run.top_seed(seed)
        where.path(CLAIM_PARTS).parent.mkdir(parents=True)
        parts_table(rng, {"p": effects[seed]}, 0.05, 0.2, 8, 0.1).to_parquet(where.path(CLAIM_PARTS))
        benchmark(run.benchmark(f"train/seed_{seed}"), 400.0)
        benchmark(run.benchmark(f"selection/seed_{seed}"), 20.0)
    pd.DataFrame({"claim": ["C9"], "recipe_verdict": ["inconclusive"], "recipe_parts": ["1 inconclusive"]}).to_parquet(
        run.path(CLAIMS_TABLE))
    pd.DataFrame({"claim": ["C9"], "part": ["p"], "decides": [True], "verdict": ["inconclusive"]}).to_parquet(
        run.path(RECIPE_PARTS))
    return run


def test_power_command_writes_its_tables_page_and_figure(tmp_path, capsys):
    run = write_run(tmp_path / "results", {2: 0.3, 5: 0.25, 1: 0.35})
    out, figures = tmp_path / "power", tmp_path / "figures"
    assert main(["power", "scale=laptop", "--results", str(run.results), "--out", str(out),
                 "--figures", str(figures)]) == 0
    plan = pd.read_parquet(out / "power.parquet")
    assert list(plan.columns) == PLAN_COLUMNS and plan["seeds"].tolist() == [3]
    assert list(pd.read_parquet(out / "power_curves.parquet").columns) == CURVE_COLUMNS
    page = (out / "power.md").read_text()
    assert "| C9 | p |" in page and "1 of 1 parts planned" in page and "0.117 CPU-hours" in page  # 420 s a seed
    assert (figures / "power.png").stat().st_size > 0 and (figures / "power.pdf").exists()
    assert (figures / "config.yaml").is_file() and (figures / "power.provenance.json").is_file()
    summary = pd.read_parquet(out / "power_claims.parquet").iloc[0]
    k = int(plan["seeds_holds_at_2delta"].iloc[0])
    assert summary["seeds_holds_at_2delta"] == k and summary["undecided"] == 1 and summary["unplanned"] == 0
    assert summary["runs_holds_at_2delta"] == pytest.approx(k * 420 / (3 * 420))  # the run: 3 seeds' jobs
    assert f"about {k} seeds" in summary["line"] and "its 1 inconclusive part if" in summary["line"] and f"- {summary['line']}" in page
    printed = capsys.readouterr().out
    assert "parts reach 80%" in printed and summary["line"] in printed


def test_power_command_without_claims_is_one_line_and_writes_nothing(tmp_path, capsys):
    out = tmp_path / "power"
    assert main(["power", "scale=laptop", "--results", str(tmp_path / "nothing"), "--out", str(out)]) == 2
    err = capsys.readouterr().err.strip()
    assert err.count("\n") == 0 and "no seed ranking" in err and not out.exists()


def test_a_run_without_training_benchmarks_is_planned_in_seeds_not_priced(tmp_path):
    run = write_run(tmp_path / "results", {2: 0.3, 5: 0.25, 1: 0.35})
    for tsv in run.benchmarks.rglob("*.tsv"):
        tsv.unlink()  # as in a sweep's point that copied its training from another point
    out = tmp_path / "power"
    assert main(["power", "scale=laptop", "--results", str(run.results), "--out", str(out),
                 "--figures", str(tmp_path / "figures")]) == 0
    plan = pd.read_parquet(out / "power.parquet")
    assert plan["seeds_holds_at_2delta"].notna().all() and plan["cpu_hours_holds_at_2delta"].isna().all()
    assert "not priced" in (out / "power.md").read_text()
    assert len(claim_curves(pd.read_parquet(out / "power_curves.parquet"))) == len(CURVE_SEEDS)


def test_where_the_run_kept_stages_each_part_shows_its_effect_along_training(tmp_path):
    run = write_run(tmp_path / "results", {2: 0.3, 5: 0.25, 1: 0.35})
    stacked = pd.DataFrame({"claim": "C9", "part": "p", "stage": [2, 1], "env_steps": [240_000, 60_000],
                            "effect": [0.3, 0.05]})
    trends = pd.DataFrame({"claim": ["C9"], "part": ["p"], "trend": ["moving toward the paper's sign"]})
    for table, name in ((stacked, CLAIMS_BY_STAGE), (trends, CLAIMS_TRENDS)):
        run.path(name).parent.mkdir(parents=True, exist_ok=True)
        table.to_parquet(run.path(name))
    out = tmp_path / "power"
    assert main(["power", "scale=laptop", "--results", str(run.results), "--out", str(out),
                 "--figures", str(tmp_path / "figures")]) == 0
    row = pd.read_parquet(out / "power.parquet").iloc[0]
    assert row["stage_effects"] == "60k: 0.05, 240k: 0.3" and row["trend"] == "moving toward the paper's sign"
    assert "| 60k: 0.05, 240k: 0.3 | moving toward the paper's sign |" in (out / "power.md").read_text()


def test_more_episodes_help_where_the_spread_is_within_seeds_and_not_where_seeds_differ():
    """Planted parts: one whose seeds agree but whose episodes scatter (tau 0, sigma large), one whose seeds differ
    (tau large, sigma small). Four times the episodes cuts the first's seeds, not the second's."""
    rng = np.random.default_rng(9)
    tables = {s: pd.concat([parts_table(rng, {"within": 0.2}, tau=0.0, sigma=0.6, n=8, delta=0.1),
                            parts_table(rng, {"between": 0.2}, tau=0.15, sigma=0.02, n=8, delta=0.1)])
              for s in range(1, 9)}
    plan = plan_parts(tables, ALPHA, COSTS).set_index("part")
    within, between = plan.loc["within"], plan.loc["between"]
    assert within["seeds_holds_at_2delta_more_episodes"] < 0.5 * within["seeds_holds_at_2delta"]
    assert between["seeds_holds_at_2delta_more_episodes"] >= 0.9 * between["seeds_holds_at_2delta"]
    k = int(between["seeds_holds_at_2delta_more_episodes"])
    assert between["cpu_hours_holds_at_2delta_more_episodes"] == pytest.approx(k * (400 + 20 + 4 * 180) / 3600)


def test_the_plan_uses_the_alpha_the_runs_claims_were_decided_at(tmp_path):
    run = write_run(tmp_path / "results", {2: 0.3, 5: 0.25, 1: 0.35})
    out = tmp_path / "power"
    assert main(["power", "scale=laptop", "--results", str(run.results), "--out", str(out),
                 "--figures", str(tmp_path / "figures")]) == 0
    at_05 = pd.read_parquet(out / "power.parquet")["seeds_holds_at_2delta"].iloc[0]
    run.path(CLAIMS_TABLE).with_name("config.yaml").write_text("analysis:\n  claims_alpha: 0.01\n")
    assert main(["power", "scale=laptop", "--results", str(run.results), "--out", str(out),
                 "--figures", str(tmp_path / "figures")]) == 0
    assert pd.read_parquet(out / "power.parquet")["seeds_holds_at_2delta"].iloc[0] > at_05  # stricter: more seeds


def ranked_parts(rng, true: float, sigma: float, n: int, delta: float, seeds=(3, 1, 4, 2)) -> dict[int, pd.DataFrame]:
    """Each seed's claim_parts row of one paired part, as the claims make it: n differences with SD sigma around
    ``true``, the signed-rank test's Hodges-Lehmann interval at 1 - 2 alpha."""
    tables = {}
    for seed in seeds:
        interval = signed_rank_interval(rng.normal(true, sigma, n), 2 * ALPHA)
        tables[seed] = pd.DataFrame([{
            "claim": "C10", "part": "food", "sign": -1.0, "effect": interval.estimate, "ci_low": interval.low,
            "ci_high": interval.high, "ci_method": f"inverts the signed-rank test, level {1 - 2 * ALPHA:.3g}",
            "n": n, "family": 1, "delta": delta, "verdict": "inconclusive"}])
    return tables


def test_the_selected_seeds_own_test_is_planned_at_its_episodes_and_priced_per_episode():
    """A paired part over 8 episodes: the own columns are the signed-rank plan at the seeds' sigma, the episodes
    named are the first that reach 80%, and they cost what the reruns cost per episode."""
    costs = COSTS._replace(episodes=8.0, rerun_episodes=6.0)
    row = plan_parts(ranked_parts(np.random.default_rng(11), -0.05, 0.3, 8, 0.1), ALPHA, costs).iloc[0]
    assert row["own_test"] == "signed-rank" and row["own_units"] == 8
    sigma = row["sigma"]
    plan = {k: own_decision_probabilities(-0.2 * (k == "holds"), sigma, 8, SIGNED_RANK, -1, 0.1, ALPHA)[k]
            for k in ("holds", "absent")}
    assert (row["own_now_holds_at_2delta"], row["own_now_absent_at_0"]) == pytest.approx(
        (plan["holds"], plan["absent"]))
    for key, theta, sought in (("holds_at_2delta", -0.2, "holds"), ("absent_at_0", 0.0, "absent")):
        k = int(row[f"own_episodes_{key}"])
        chances = [own_decision_probabilities(theta, sigma, n, SIGNED_RANK, -1, 0.1, ALPHA)[sought] for n in (k - 1, k)]
        assert chances[0] < 0.8 <= chances[1], key
        assert row[f"own_cpu_hours_{key}"] == pytest.approx(k * 180 / 6 / 3600)  # 180 s of reruns at 6 episodes
    assert row["own_episodes_holds_at_2delta"] > 8 and row["own_now_holds_at_2delta"] < 0.8


def test_own_episodes_follow_the_selected_seeds_units_per_episode():
    """A part over 16 units at 8 episodes a condition (two conditions' episodes, say) needs half as many episodes
    per condition as units; one seed alone still plans its own test from its own interval."""
    tables = ranked_parts(np.random.default_rng(12), 0.0, 0.3, 16, 0.1, seeds=(3,))
    row = plan_parts(tables, ALPHA, COSTS._replace(episodes=8.0, rerun_episodes=8.0)).iloc[0]
    assert np.isnan(row["seeds_holds_at_2delta"]) and "1 seed(s)" in row["note"]
    units = units_needed(-0.2, float(own_standard_error(tables[3]["ci_low"][0], tables[3]["ci_high"][0], SIGNED_RANK,
                                                        16, ALPHA) * 4), SIGNED_RANK, -1, 0.1, ALPHA, "holds")
    assert row["own_episodes_holds_at_2delta"] == np.ceil(units / 2)


def test_a_part_whose_own_test_makes_no_interval_is_not_planned_and_says_why():
    rng = np.random.default_rng(13)
    tables = {s: parts_table(rng, {"p": 0.3}, 0.05, 0.2, 8, 0.1).assign(ci_method="") for s in (1, 2, 3)}
    row = plan_parts(tables, ALPHA, COSTS).iloc[0]
    assert row["own_test"] == "" and np.isnan(row["own_now_holds_at_2delta"]) and "no interval" in row["note"]
    assert np.isfinite(row["now_holds_at_2delta"])  # the recipe's plan does not need it


def test_power_command_prices_the_selected_seeds_episodes_at_the_recorded_episodes(tmp_path):
    """The episodes per condition come from the config.yaml the run's claims recorded (here 8 for the selected seed,
    4 for the reruns), and an episode costs the reruns' CPU time over their episodes (C9's assay, patchy4, rerun
    by both other seeds in one job of 120 s)."""
    run = write_run(tmp_path / "results", {2: 0.3, 5: 0.25, 1: 0.35})
    benchmark(run.benchmark(top_seed_group("patchy4")), 120.0)
    run.path(CLAIMS_TABLE).with_name("config.yaml").write_text(
        "analysis:\n  claims_alpha: 0.05\nscale:\n  max_episodes: 8\n  top_seed_episodes: 4\n")
    out = tmp_path / "power"
    assert main(["power", "scale=laptop", "--results", str(run.results), "--out", str(out),
                 "--figures", str(tmp_path / "figures")]) == 0
    row = pd.read_parquet(out / "power.parquet").iloc[0]
    assert row["own_test"] == "t" and row["own_units"] == 8
    episodes = int(row["own_episodes_holds_at_2delta"])
    assert row["own_cpu_hours_holds_at_2delta"] == pytest.approx(episodes * 60 / 4 / 3600)
    assert "| t | " in (out / "power.md").read_text()


def test_power_takes_the_run_as_its_folder_or_its_name(tmp_path, monkeypatch, capsys):
    """``efish power results/laptop`` (and ``efish power laptop`` from the folder above results/) reads that run, as
    ``efish watch`` does, beside Hydra overrides; the recorded scale names it on the page."""
    run = write_run(tmp_path / "results", {2: 0.3, 5: 0.25, 1: 0.35})
    run.path(CLAIMS_TABLE).with_name("config.yaml").write_text("scale:\n  name: study\n")
    monkeypatch.chdir(tmp_path)
    assert main(["power", "results/laptop", "--figures", "figs"]) == 0
    page = run.path(CLAIMS_TABLE).with_name("power.md")
    assert page.is_file() and "Run laptop at scale study" in page.read_text()
    page.unlink()
    assert main(["power", "laptop", "scale=laptop", "--figures", "figs"]) == 0 and page.is_file()
    assert main(["power", "results/laptop", "--results", "results/laptop"]) == 2
    assert "give the run once" in capsys.readouterr().err
    with pytest.raises(SystemExit):
        main(["power", "results/laptop", "results/smoke"])
    assert "one run at a time" in capsys.readouterr().err


def test_a_homing_draw_is_priced_with_the_homing_jobs_not_as_a_foraging_seed(tmp_path):
    """Planted benchmarks of a run with two more draws of the homing recipes: a draw costs its recipes' trainings and
    its seed's rerun of homing with them (and that rerun's analyses); a foraging seed's price keeps neither."""
    run = Run("r", results_root=tmp_path)
    for seed, cpu in ((1, 300.0), (2, 500.0)):
        benchmark(run.benchmark(f"train/seed_{seed}"), cpu)
        benchmark(run.benchmark(f"selection/seed_{seed}"), 10.0)
    for name, cpu in (("homing_draw_2", 100.0), ("homing_raycast_draw_2", 50.0), ("homing_draw_3", 120.0),
                      ("homing_raycast_draw_3", 30.0)):
        benchmark(run.benchmark(f"train/{name}"), cpu)
    benchmark(run.benchmark(top_seed_group("patchy4")), 120.0)  # both other seeds' foraging rerun, one job
    for seed, (assay, analysis) in ((2, (40.0, 10.0)), (3, (20.0, 10.0))):
        benchmark(run.top_seed(seed).benchmark("assays/homing"), assay)  # the seed's rerun with its draw
        benchmark(run.top_seed(seed).benchmark("analysis/dynamics/homing"), analysis)
        benchmark(run.top_seed(seed).benchmark("analysis/behaviour/patchy4"), 5.0)
        benchmark(run.top_seed(seed).benchmark("claims"), 20.0)
    costs = run_costs(run, [1, 2], other_top_seeds=2, episodes=(8.0, 6.0))
    assert costs.rerun_s == (120 + 2 * 5 + 2 * 20) / 2  # no homing in a foraging seed's reruns
    assert (costs.draw_train_s, costs.draw_rerun_s) == (150.0, 40.0)  # per draw: both recipes; per rerunning seed
    assert costs.drawn_assays == ("homing",) and costs.rerun_assays == ("patchy4",)
    assert costs.draws("C2") and not costs.draws("C9") and "homing draws: training 2, reruns 2" in costs.seeds_timed
    assert costs.design_hours(5, claim="C2") == pytest.approx(5 * (150 + 40) / 3600)
    assert costs.design_hours(5, MORE_EPISODES, "C2") == pytest.approx(5 * (150 + 4 * 40) / 3600)
    assert costs.design_hours(5, claim="C9") == pytest.approx(5 * (400 + 10 + 85) / 3600)
    assert costs.episode_hours(12, "C2") == pytest.approx(12 * 40 / 6 / 3600)
    assert costs.episode_hours(12, "C9") == pytest.approx(12 * 85 / 6 / 3600)
    assert np.isnan(costs.episode_hours(12, "C10"))  # no top seed reran the ablations: its price is not measured
    rng = np.random.default_rng(14)
    tables = {s: parts_table(rng, {"aligned": 0.3}, 0.05, 0.2, 8, 0.1).assign(claim="C2") for s in (1, 2, 3)}
    row = plan_parts(tables, ALPHA, costs).iloc[0]
    assert row["draws"] and row["cpu_hours_holds_at_2delta"] == pytest.approx(
        row["seeds_holds_at_2delta"] * 190 / 3600)
    page = power_markdown(plan_parts(tables, ALPHA, costs), costs, "", ALPHA)
    assert f"One more draw of the homing recipes, which the homing claims are decided over, costs {190 / 3600:.3g}" in page
    # a per-seed rerun without a draw trained is not a draw's (a layout without groups): all a foraging seed's
    for tsv in run.benchmark("train/x").parent.glob("*_draw_*.tsv"):
        tsv.unlink()
    plain = run_costs(run, [1, 2], other_top_seeds=2)
    assert plain.drawn_assays == () and plain.rerun_s == (120 + 2 * 5 + 2 * 20 + 40 + 10 + 20 + 10) / 2
    assert not plain.draws("C2") and np.isnan(plain.draw_train_s)
