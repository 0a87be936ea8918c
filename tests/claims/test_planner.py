"""The planner reads a run's per-seed parts tables and benchmark files and plans each part over seeds."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest
from scipy import stats

from efish.claims.planner import PLAN_COLUMNS, RunCosts, plan_parts, run_costs
from efish.claims.power import decision_probabilities
from efish.layout import Run

ALPHA = 0.05


def parts_table(rng, seed_effects: dict[str, float], tau: float, sigma: float, n: int, delta: float) -> pd.DataFrame:
    """One seed's claim_parts rows: each part's effect drawn around its true value (between-seed tau), its
    interval the t interval at 1 - 2 alpha of n units with SD sigma."""
    rows = []
    for part, true in seed_effects.items():
        data = rng.normal(rng.normal(true, tau), sigma, n)
        half = stats.t.ppf(1 - ALPHA, n - 1) * data.std(ddof=1) / np.sqrt(n)
        rows.append({"claim": "C9", "part": part, "sign": 1.0, "effect": data.mean(), "ci_low": data.mean() - half,
                     "ci_high": data.mean() + half, "ci_method": "t", "n": n, "family": 1, "delta": delta,
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
    assert costs.design_hours(9) == pytest.approx(9 * 490 / 3600) and np.isnan(costs.design_hours(None))
    with pytest.raises(ValueError, match="no training benchmarks"):
        run_costs(Run("empty", results_root=tmp_path), [1], 0)
