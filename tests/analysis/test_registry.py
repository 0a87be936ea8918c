"""The analysis registry: every analysis runs on rollout-shaped tables and writes what it declares."""

from __future__ import annotations

from types import SimpleNamespace

import numpy as np
import pandas as pd
import pytest

from efish.analysis.registry import (
    ANALYSES,
    ROLLOUT_TABLES,
    Analysis,
    analyses_for,
    get,
    read_tables,
    run,
    tables_written,
)
from efish.analysis.stats import STAT_COLUMNS
from efish.config import config_dir
from efish.rollout.schema import SCHEMAS, to_table

from ..helpers import (
    DEFAULT_FPS,
    HALF_FPS,
    cfg_with,
    conditions_of,
    planted_rate_tables,
    recorded_table,
    rollout_tables,
)

#: The assays of docs/methods/assays.md (config/assay/<name>.yaml as they land).
SPEC_ASSAYS = {"homing", "patchy4", "uniform4", "wide2", "square2", "ablation4", "ablation1", "collective", "mute",
               "npatch", "food_scarcity", "onepatch", "bot", "groupsize"}


#: Statistic tables that test the conditions of one assay -> condition names of that assay to run them on.
ASSAY_SPECIFIC = {("onepatch", "role_tests"): ("A_gt_B", "A_alone_75", "B_alone_25"),
                  ("onepatch", "reach_tests"): ("bot0.5_B0.5_rate0_frozen", "bot0.5_B0.5_rate1_moving"),
                  ("dynamics", "size_tests"): ("n2_K", "n4_K", "n2_noK", "n4_noK")}
#: The assay whose recorded conditions (conditions.parquet) say who is who in those tests.
RECORDED = {("onepatch", "role_tests"): "onepatch", ("onepatch", "reach_tests"): "bot",
            ("dynamics", "size_tests"): "groupsize"}


def settings_for(name: str):
    """The analysis settings an analysis of one of its assays runs under (the homing analysis with the homing
    assay's)."""
    return (cfg_with("assay=homing") if name == "homing" else cfg_with("scale=smoke")).analysis


@pytest.fixture(scope="module")
def tables():
    return rollout_tables(error_angles=True)


def test_the_synthetic_tables_are_shaped_like_the_rollout(tables):
    for name in (*SCHEMAS, "hidden"):
        if name != "conditions":  # synthetic tables get a recorded one per assay (helpers.conditions_of)
            to_table(tables[name], name)


@pytest.mark.parametrize("name", list(ANALYSES))
def test_every_analysis_writes_its_declared_tables(name, tables):
    analysis = get(name)
    homing = {"steps": tables["steps"].query("agent < 2").replace({"condition": {"control": "electric",
                                                                                  "treated": "raycast"}}),
              "conditions": conditions_of("homing")}
    out = run(name, homing if name == "homing" else tables, settings_for(name))
    assert list(out) == list(analysis.outputs)
    for table, df in out.items():
        assert isinstance(df, pd.DataFrame) and len(df) > 0, table
    for table in analysis.stats:
        assert set(STAT_COLUMNS) <= set(out[table].columns), table
        if (name, table) in ASSAY_SPECIFIC:  # a test of one assay's conditions: a NaN row that says why elsewhere
            assert out[table]["reason"].astype(bool).all(), f"{name}/{table} tested conditions it does not know"
            own = rollout_tables(conditions=ASSAY_SPECIFIC[name, table])
            if (name, table) in RECORDED:
                own["conditions"] = conditions_of(RECORDED[name, table])
            own = run(name, own, settings_for(name))[table]
            assert np.isfinite(own["p"]).any(), f"{name}/{table} has no finite p on its assay's conditions"
        else:
            assert np.isfinite(out[table]["p"]).any(), f"{name}/{table} has no finite p"


def test_statistics_find_the_planted_effects(tables):
    """Bigger agents eat, bite and discharge more in the synthetic tables; the statistic rows say so."""
    settings = cfg_with().analysis
    behaviour = run("behaviour", tables, settings)
    fit = behaviour["food_vs_size"].set_index("group")
    assert (fit["effect"] > 0).all() and (fit["test"] == "ols").all()
    sizes = behaviour["size_tests"].set_index(["measure", "group"])
    assert (sizes.loc["eod_probability", "effect"] > 0.5).all() and (sizes.loc["eod_probability", "p"] < 0.05).all()
    tests = behaviour["condition_tests"]
    assert set(tests["measure"]) == {"food_total", "theil_t", "eod_probability", "mean_nn_dist_cm", "bites"}
    assert (tests["group"] == "treated").all() and (tests["control"] == "control").all()
    assert (tests["n"] == 3).all() and (tests["n_control"] == 3).all()
    roles = run("interactions", tables, settings)["size_tests"].set_index(["measure", "condition"])
    assert (roles.loc["bite", "group"] == "biter").all() and (roles.loc["bite", "effect"] > 0).all()


def test_tables_the_rollout_does_not_record_yet_give_a_reason_not_an_error(tables):
    steps, settings = tables["steps"].drop(columns="bite_target"), cfg_with().analysis
    out = run("interactions", {"steps": steps, "conditions": tables["conditions"]}, settings)
    assert out["labels"]["reason"].eq("").all()
    for name in ("bouts", "bite_sizes", "size_tests"):
        assert "bite_target" in out[name].loc[0, "reason"], name
    assert set(STAT_COLUMNS) <= set(out["size_tests"].columns)
    assert "bite_target" in run("behaviour", {**tables, "steps": steps}, settings)["bite_matrix"].loc[0, "reason"]
    electric_only = steps.query("condition == 'control' and agent < 2").assign(condition="electric")
    homing = run("homing", {"steps": electric_only.drop(columns=["err_morm_rad", "err_amp_rad", "err_knollen_rad"]),
                            "conditions": conditions_of("homing")}, settings_for("homing"))
    assert "err_morm_rad" in homing["error_histogram"].loc[0, "reason"]
    assert homing["perception"]["reason"].eq("no group besides the control").all()  # no raycast condition yet


def test_settings_and_the_recorded_rate_reach_the_functions(tables, tmp_path):
    """The analysis settings come from the job, the frame rate from the conditions the assay recorded."""
    real = tmp_path / "real.csv"
    pd.DataFrame({"idi_ms": (np.random.default_rng(1).pareto(1.5, 2000) + 1) * 20.0}).to_csv(real, index=False)
    default = run("signalling", tables, cfg_with().analysis)
    assert default["power_law"].set_index("source").loc["real_fish", "reason"].startswith("no real-fish IDI table")
    settings = cfg_with("analysis.rate_bins=4", "analysis.idi_bins=7", f"analysis.real_fish_idis={real}",
                        "analysis.claims_event_window=[-5,20]", "analysis.claims_baseline_window=[-60,-30]").analysis
    out = run("signalling", {**tables, "conditions": recorded_table(("control", "treated"), "env.fps=100")}, settings)
    assert out["rate_by_distance"]["bin"].max() <= 3 and out["rate_by_distance_episodes"]["bin"].max() <= 3
    windows = out["peri_event_episodes"][["event_lo", "event_hi", "baseline_lo", "baseline_hi"]].drop_duplicates()
    assert windows.values.tolist() == [[-5, 20, -60, -30]]  # claim C6's windows are the analysis job's
    assert out["idi_histogram"].groupby(["source", "condition"], dropna=False).size().eq(7).all()
    assert np.isfinite(out["power_law"].set_index("source").loc["real_fish", "alpha"])
    np.testing.assert_allclose(out["idis"]["idi_ms"], out["idis"]["idi_steps"] * 10.0)  # 1000 / env.fps


def test_the_per_unit_tables_the_claims_read_follow_the_jobs_settings(tables):
    """The per-episode tables the claims select rows of (issue 38) are the analysis's, under its settings: the aligned
    band (homing), the bout range (interactions), the PLSC distance edges (dynamics)."""
    homing = {"steps": tables["steps"].query("agent < 2").replace({"condition": {"control": "electric"}})
              .query("condition == 'electric'"), "conditions": conditions_of("homing")}
    narrow, wide = (run("homing", homing, cfg_with("assay=homing", f"analysis.claims_aligned_rad={a}").analysis)
                    ["alignment_episodes"] for a in (0.1, 1.5))
    assert len(narrow) and (narrow["aligned_fraction"] < wide["aligned_fraction"]).all()
    assert narrow["aligned_excess"].equals(narrow["aligned_fraction"] - narrow["straight_aligned_fraction"])
    within = []
    for bout_cm in (10.0, 30.0):
        out = run("interactions", tables, cfg_with(f"analysis.bout_cm={bout_cm}").analysis)
        pooled = out["bite_rate_episodes"].groupby(["condition", "label"])[["n_steps", "bites"]].sum()
        by_class = out["bite_rate_by_class"].set_index(["condition", "label"])[["n_steps", "bites"]]
        assert pooled.loc[by_class.index].equals(by_class)
        within.append(pooled["n_steps"].sum())
    assert within[0] < within[1]
    dynamics = run("dynamics", tables, cfg_with("scale=smoke", "analysis.plsc_edges_cm=[20.0]").analysis)
    bins = dynamics["plsc_episodes"]
    assert bins.groupby(["condition", "episode"]).size().eq(2).all() and set(bins["hi_cm"]) == {20.0, np.inf}
    assert {"role", "size", "wideband_power"} <= set(dynamics["power_roles"].columns)


def test_a_planted_eod_rate_comes_out_in_hz_at_each_recorded_frame_rate():
    """Issue 38: one condition of the assay recorded at half the default env.fps. Every agent discharges on every
    5th step, so its rate is fps / 5: 16.6 Hz at 83 steps per second, 8.3 Hz at 41.5. The signalling tables say so
    in each condition's own Hz and ms, the dynamics power is per Hz of each condition's rate, and nothing of the
    rate comes from the job's settings (the schema's default env.fps would give 16.6 Hz for both)."""
    settings = cfg_with("scale=smoke").analysis
    tables = planted_rate_tables(period=5)
    fps = {"default": DEFAULT_FPS, "slow": HALF_FPS}
    assert HALF_FPS == DEFAULT_FPS / 2 and fps["slow"] == 41.5
    out = run("signalling", tables, settings)

    def of(table: pd.DataFrame, condition: str) -> pd.DataFrame:
        return table[table["condition"] == condition]
    for cond, rate in fps.items():
        by_distance = of(out["rate_by_distance"], cond).dropna(subset=["mean_hz"])
        assert len(by_distance) and by_distance["mean_hz"].to_numpy() == pytest.approx(rate / 5)
        peri = of(out["peri_event"], cond).dropna(subset=["mean_hz"])
        assert len(peri) and peri["mean_hz"].to_numpy() == pytest.approx(rate / 5)
        np.testing.assert_allclose(peri["lag_ms"], peri["lag"] * 1000.0 / rate)
        # per episode (claims C5, C6): the same rate in every bin, and no change around eating
        episodes = of(out["rate_by_distance_episodes"], cond).dropna(subset=["rate_hz"])
        assert len(episodes) and episodes["rate_hz"].to_numpy() == pytest.approx(rate / 5)
        change = of(out["peri_event_episodes"], cond)
        change = change[change["event"] == "ate"]
        assert len(change) == 3 and change["change_hz"].to_numpy() == pytest.approx(0.0, abs=1e-9)
        ids = of(out["idis"], cond)
        assert (ids["idi_steps"] == 5).all() and ids["idi_ms"].to_numpy() == pytest.approx(5000.0 / rate)
        fit = of(out["power_law"], cond).iloc[0]  # the agents' fit (the real fish's has no condition)
        assert fit["xmin"] == pytest.approx(fit["xmin_steps"] * 1000.0 / rate)
    # agent 0 discharges on every 4th step: 0.05 x fps Hz above every partner of its pairs, 0 between the others
    leader = run("signalling", planted_rate_tables(period=5, leader_period=4), settings)["rate_advantage"]
    for cond, rate in fps.items():
        rows = of(leader, cond)
        assert (rows["agent"] == 0).any() and (rows["agent"] > 0).any()
        expected = np.where(rows["agent"] == 0, 0.05 * rate, 0.0)
        np.testing.assert_allclose(rows["rate_advantage_hz"], expected, atol=1e-9)
    # the same hidden states at half the steps per second: twice the spectral density per Hz
    dims = run("dynamics", tables, settings)["dimensionality"].set_index(["condition", "episode", "agent"])
    ratio = dims.loc["slow", "wideband_power"] / dims.loc["default", "wideband_power"]
    assert len(ratio) and ratio.to_numpy() == pytest.approx(2.0)


def test_the_control_is_the_first_recorded_condition_present(tables):
    """Condition tests compare with the assay's first recorded condition; when it is absent, with the next one
    recorded (not the first in sorted order)."""
    recorded = recorded_table(("treated", "control"))
    out = run("behaviour", {**tables, "conditions": recorded}, cfg_with().analysis)["condition_tests"]
    assert (out["control"] == "treated").all() and (out["group"] == "control").all()
    three = recorded_table(("absent", "treated", "control"))
    out = run("behaviour", {**tables, "conditions": three}, cfg_with().analysis)["condition_tests"]
    assert (out["control"] == "treated").all()


def test_scheduling_follows_the_tables_an_assay_writes():
    assert [a.name for a in analyses_for("patchy4", ROLLOUT_TABLES)] == ["signalling", "behaviour", "interactions"]
    with_hidden = tables_written(SimpleNamespace(record_hidden=True))
    assert "dynamics" in [a.name for a in analyses_for("patchy4", with_hidden)]
    assert tables_written(cfg_with("assay=mute").assay) == ROLLOUT_TABLES
    assert "hidden" in tables_written(cfg_with("assay=patchy4").assay)


def test_the_registry_names_spec_assays_rollout_tables_and_unique_outputs():
    shipped = {p.stem for p in (config_dir() / "assay").glob("*.yaml")} - {"selection"}
    for a in ANALYSES.values():
        assert set(a.assays) <= SPEC_ASSAYS, a.name
        assert set(a.reads) <= {*ROLLOUT_TABLES, "hidden"}, a.name
        assert set(a.stats) <= set(a.outputs) and len(set(a.outputs)) == len(a.outputs), a.name
        assert not set(a.outputs) & {*SCHEMAS, "hidden"}, a.name  # a rollout table's name means its schema
    assert shipped <= {s for a in ANALYSES.values() for s in a.assays}  # every shipped assay is analysed
    for a in ANALYSES.values():  # every job reads the assay's record and writes the settings it ran with
        assert "conditions" in a.reads and a.written == (*a.outputs, "analysis_settings"), a.name
    with pytest.raises(ValueError, match="must read 'conditions'"):
        Analysis("blind", lambda t, a, c: {}, ("steps",), ("patchy4",), ("x",))
    with pytest.raises(ValueError, match="'analysis_settings' is the job's settings table"):
        Analysis("clash", lambda t, a, c: {}, ("steps", "conditions"), ("patchy4",), ("analysis_settings",))


def test_bad_names_and_missing_tables_are_one_line(tmp_path, tables):
    with pytest.raises(ValueError, match="unknown analysis 'nope': choose one of signalling"):
        get("nope")
    tables["steps"].to_parquet(tmp_path / "steps.parquet")
    tables["conditions"].to_parquet(tmp_path / "conditions.parquet")
    with pytest.raises(ValueError, match=r"needs .*episodes\.parquet, .*food\.parquet, which does not exist"):
        read_tables("behaviour", tmp_path)
    with pytest.raises(ValueError, match=r"needs the tables \['hidden'\]"):
        run("dynamics", {"steps": tables["steps"], "conditions": tables["conditions"]}, cfg_with().analysis)
    with pytest.raises(ValueError, match=r"the steps table holds conditions \['treated'\] that the assay's "
                                         r"conditions table does not record \(control\)"):
        run("behaviour", {**tables, "conditions": recorded_table(("control",))}, cfg_with().analysis)
