"""``efish bench scaling`` reports what it promises on tiny sizes (never timing asserts)."""

from __future__ import annotations

import dataclasses

import pandas as pd
import pytest

from efish.bench.scaling import COLUMNS, bench_scaling, plot_scaling, scaling_cases

from ..helpers import cfg_with

TINY = ("bench.scaling_sizes_cm=[40.0,80.0]", "bench.scaling_crowded_multiplier=3.0", "bench.scaling_agents=[1,2]",
        "bench.scaling_envs=1", "bench.scaling_agent_steps=8", "bench.scaling_exact_agent_steps=2",
        "bench.reference_rounds=1")


def test_cases_cover_both_sweeps_and_the_crowded_arena():
    cases = scaling_cases(cfg_with(*TINY))
    assert [c.case for c in cases] == ["40x40", "80x80", "40x40 crowded x3", "1 agent", "2 agents"]
    assert [c.sweep for c in cases] == ["pellets"] * 3 + ["agents"] * 2
    assert cases[2].food_multiplier == 3.0 and cases[2].width_cm == 40.0


def test_no_sizes_is_a_clear_error():
    cfg = cfg_with(*TINY)
    with pytest.raises(ValueError, match="scaling_sizes_cm"):
        scaling_cases(dataclasses.replace(cfg, bench=dataclasses.replace(cfg.bench, scaling_sizes_cm=[])))


def test_table_has_a_row_per_case_with_rates_errors_and_a_figure(tmp_path):
    df = bench_scaling(cfg_with(*TINY))
    assert list(df.columns) == list(COLUMNS) and len(df) == 5
    assert (df["fast_agent_steps_per_s"] > 0).all() and (df["exact_agent_steps_per_s"] > 0).all()
    assert (df["max_abs_error"] <= 1e-6).all()
    pellets = df.set_index("case")["pellets"]
    assert pellets["80x80"] > pellets["40x40"] and pellets["40x40 crowded x3"] > pellets["40x40"]
    assert df.loc[df["sweep"] == "agents", "n_agents"].tolist() == [1, 2]
    plot_scaling(df, tmp_path / "s.png")
    plot_scaling(pd.DataFrame(df[df["sweep"] == "pellets"]), tmp_path / "only_pellets.png")  # a missing sweep says so
    assert (tmp_path / "s.png").stat().st_size > 0 and (tmp_path / "only_pellets.png").stat().st_size > 0
