"""Signalling analyses with known answers: IDIs, power-law fits, EOD rate vs distance and around events."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

from efish.analysis.signalling import (
    EPISODE_BIN_COLUMNS,
    PERI_EPISODE_COLUMNS,
    eod_rate_by_distance,
    eod_rate_by_distance_episodes,
    fit_power_law,
    idi_histogram,
    idis,
    load_real_idis,
    peri_event_episodes,
    peri_event_rate,
    rate_advantage_vs_size,
    xmin_in_steps,
)

FPS = 83.0  # steps per second the synthetic agents were simulated at (env.fps's default)
STEP_MS = 1000.0 / FPS


def agent_steps(eod, agent=0, episode=0, **columns) -> pd.DataFrame:
    """One agent-episode with the given EOD train; other columns constant unless given."""
    eod = np.asarray(eod, dtype=bool)
    base = {"condition": "c", "episode": episode, "agent": agent, "t": np.arange(eod.size), "eod": eod,
            "ate": False, "bit": False, "was_bitten": False, "size": 0.5, "x_cm": 10.0, "y_cm": 10.0,
            "dist_agent_cm": 50.0, "dist_food_cm": 5.0, "dist_wall_cm": 5.0}
    return pd.DataFrame({**base, **columns})


def test_idis_are_step_differences_per_agent_episode():
    steps = pd.concat([agent_steps([1, 0, 0, 1, 1, 0]), agent_steps([0, 1, 0, 0, 0, 1], agent=1)])
    out = idis(steps.sample(frac=1.0, random_state=0), fps=FPS)  # row order must not matter
    assert out["idi_steps"].tolist() == [3, 1, 4] and out["agent"].tolist() == [0, 0, 1]
    np.testing.assert_allclose(out["idi_ms"], np.array([3, 1, 4]) * STEP_MS)
    assert idis(agent_steps([0, 0, 1]), fps=FPS).empty
    # per condition: each condition's IDIs in its own ms
    two = pd.concat([agent_steps([1, 0, 1]), agent_steps([1, 0, 1]).assign(condition="slow")])
    assert idis(two, fps={"c": 100.0, "slow": 50.0})["idi_ms"].tolist() == [20.0, 40.0]
    with pytest.raises(ValueError, match="no recorded value for condition 'slow'"):
        idis(two, fps={"c": 100.0})


def test_power_law_alpha_recovered_on_1e4_samples():
    u = np.random.default_rng(0).uniform(size=10_000)
    x = 12.0 * (1 - u) ** (-1 / (2.5 - 1))  # inverse CDF of a continuous power law, alpha 2.5, xmin 12
    fit = fit_power_law(x)
    assert abs(fit["alpha"] - 2.5) < 0.1 and fit["n"] == 10_000 and fit["xmin"] == 12.0
    assert fit["R_exponential"] > 0 and fit["p_exponential"] < 0.05  # a power law beats an exponential


def test_discrete_power_law_of_whole_steps():
    """IDIs are whole steps: a discrete fit from xmin = 1 step recovers a zeta law's alpha and prefers it to an
    exponential, and rejects it for geometric (memoryless) steps; 12 ms is 1 step of 12.048 ms."""
    from scipy import stats as sps

    x = sps.zipf(2.5).rvs(20_000, random_state=1)
    fit = fit_power_law(x, 1, discrete=True)
    assert abs(fit["alpha"] - 2.5) < 0.1 and fit["R_exponential"] > 0 and fit["p_exponential"] < 0.05
    geometric = fit_power_law(np.random.default_rng(2).geometric(0.3, 20_000), 1, discrete=True)
    assert geometric["R_exponential"] < 0 and geometric["p_exponential"] < 0.05
    assert xmin_in_steps(12.0, 12.048) == 1 and xmin_in_steps(24.1, 12.048) == 3 and xmin_in_steps(0.0, 12.048) == 1


def test_fewer_alternatives_change_no_comparison():
    """Comparing with the exponential alone (the C4 bootstrap) gives the full fit's alpha and R_exponential and
    leaves the lognormal's numbers NaN."""
    from scipy import stats as sps

    x = sps.zipf(2.2).rvs(5_000, random_state=4)
    full, alone = fit_power_law(x, 1, discrete=True), fit_power_law(x, 1, discrete=True, alternatives=("exponential",))
    assert (alone["alpha"], alone["R_exponential"], alone["p_exponential"]) == (
        full["alpha"], full["R_exponential"], full["p_exponential"])
    assert np.isnan(alone["R_lognormal"]) and np.isnan(alone["p_lognormal"]) and np.isfinite(full["R_lognormal"])


def test_lognormal_data_prefer_lognormal():
    x = np.random.default_rng(0).lognormal(mean=4.0, sigma=0.8, size=10_000)
    fit = fit_power_law(x)
    assert fit["R_lognormal"] < 0 and fit["p_lognormal"] < 0.05 and fit["reason"] == ""


@pytest.mark.parametrize(("data", "reason"), [([], "fewer than 10"), ([np.nan] * 20, "fewer than 10"),
                                              ([5.0] * 50, "fewer than 10"), ([20.0] * 50, "all IDIs >= xmin")])
def test_power_law_degenerate(data, reason):
    fit = fit_power_law(np.asarray(data))
    assert np.isnan(fit["alpha"]) and np.isnan(fit["R_lognormal"]) and fit["reason"].startswith(reason)


def test_idi_histogram_density_integrates_to_one():
    h = idi_histogram(np.random.default_rng(0).uniform(15, 2000, 500))
    assert len(h) == 50 and h["count"].sum() == 500
    assert np.sum(h["density"] * (h["bin_hi_ms"] - h["bin_lo_ms"])) == pytest.approx(1.0)
    assert h["bin_lo_ms"].iloc[0] == 10.0 and h["bin_hi_ms"].iloc[-1] == pytest.approx(3000.0)


def test_eod_rate_by_distance_bins_mean_and_drops_sparse_bins():
    t = 400
    dist = np.where(np.arange(t) < 200, 1.0, 9.0)  # two long stretches: near and far from food
    dist[200:230] = np.nan                          # no food in sight while the rate window changes over
    dist[300:303] = 5.0                             # three samples in a middle bin: dropped (< 5)
    steps = agent_steps(np.arange(t) < 215, dist_food_cm=dist)  # fires while near (and a bit after)
    out = eod_rate_by_distance(steps, "food", fps=FPS)
    assert out["bin"].tolist() == [1, 13] and (out["reason"] == "").all()
    assert out["mean_hz"].tolist() == pytest.approx([83.0, 0.0])
    assert out.loc[0, "bin_lo_cm"] == pytest.approx(2 / 3) and out.loc[0, "n"] == 200 - 10  # full windows only
    assert out["sem_hz"].tolist() == pytest.approx([0.0, 0.0])


def test_eod_rate_by_distance_degenerate_and_errors():
    far = eod_rate_by_distance(agent_steps(np.ones(50), dist_food_cm=np.nan), "food", fps=FPS)
    assert len(far) == 1 and np.isnan(far.loc[0, "mean_hz"]) and "no distance bin" in far.loc[0, "reason"]
    assert eod_rate_by_distance(agent_steps([]), "wall", fps=FPS).loc[0, "reason"] == "empty steps table"
    with pytest.raises(ValueError, match="to must be one of"):
        eod_rate_by_distance(agent_steps(np.ones(50)), "pellet", fps=FPS)
    with pytest.raises(ValueError, match="dist_agent_cm"):
        eod_rate_by_distance(agent_steps(np.ones(50)).drop(columns="dist_agent_cm"), "agent", fps=FPS)


def test_eod_rate_by_distance_episodes_averages_each_episodes_agents():
    """Per episode and bin: each agent's mean rate over its steps in the bin, then their mean. Episode 0: agent 0
    fires on every step (83 Hz) and agent 1 never, both 1 cm from food (bin 1): 41.5 Hz from 2 agents; agent 1 also
    spends 3 steps at 5 cm (bin 7), too few (< 5): left out. Episode 1: one agent fires on every other step at 9 cm
    (bin 13): 41.5 Hz."""
    t = 100
    middle = np.where((np.arange(t) >= 40) & (np.arange(t) < 43), 5.0, 1.0)
    steps = pd.concat([agent_steps(np.ones(t), dist_food_cm=1.0), agent_steps(np.zeros(t), agent=1, dist_food_cm=middle),
                       agent_steps(np.arange(t) % 2 == 0, episode=1, dist_food_cm=9.0)], ignore_index=True)
    out = eod_rate_by_distance_episodes(steps, "food", fps=FPS)
    assert list(out.columns) == EPISODE_BIN_COLUMNS and (out["reason"] == "").all() and (out["to"] == "food").all()
    assert out[["episode", "bin", "n_agents"]].values.tolist() == [[0, 1, 2], [1, 13, 1]]
    assert out["rate_hz"].tolist() == pytest.approx([41.5, 41.5])
    assert out.loc[0, "bin_lo_cm"] == pytest.approx(2 / 3) and out.loc[1, "bin_hi_cm"] == pytest.approx(28 / 3)
    # one agent-episode: the per-episode rates are eod_rate_by_distance's means (the same rates, bins and steps)
    one = agent_steps(np.random.default_rng(3).random(400) < 0.3, dist_food_cm=np.linspace(0, 10, 400))
    pooled, episodes = eod_rate_by_distance(one, "food", fps=FPS), eod_rate_by_distance_episodes(one, "food", fps=FPS)
    assert episodes["bin"].tolist() == pooled["bin"].tolist() and len(pooled) == 15
    assert episodes["rate_hz"].tolist() == pooled["mean_hz"].tolist()
    assert episodes["bin_mid_cm"].tolist() == pooled["bin_mid_cm"].tolist()


def test_eod_rate_by_distance_episodes_degenerate_and_errors():
    far = pd.concat([agent_steps(np.ones(50), dist_food_cm=np.nan), agent_steps(np.ones(50)).assign(condition="d")])
    out = eod_rate_by_distance_episodes(far, "food", fps={"c": FPS, "d": FPS})
    assert out["condition"].tolist() == ["c", "d"] and np.isnan(out.loc[0, "rate_hz"])
    assert out.loc[0, "reason"] == "no agent-episode has 5 steps in a food distance bin" and out.loc[0, "n_agents"] == 0
    empty = eod_rate_by_distance_episodes(agent_steps([]), "wall", fps=FPS)
    assert len(empty) == 1 and empty.loc[0, "reason"] == "empty steps table" and list(empty.columns) == EPISODE_BIN_COLUMNS
    with pytest.raises(ValueError, match="to must be one of"):
        eod_rate_by_distance_episodes(agent_steps(np.ones(50)), "pellet", fps=FPS)


def test_peri_event_rate_rises_after_events():
    t, events = 1000, [200, 450, 700]
    ate, eod = np.zeros(t, bool), np.zeros(t, bool)
    for e in events:
        ate[e] = True
        eod[e:e + 40] = True  # fires for 40 steps after eating
    out = peri_event_rate(agent_steps(eod, ate=ate), "ate", fps=FPS).set_index("lag")
    assert out.loc[20, "mean_hz"] == pytest.approx(83.0) and out.loc[-50, "mean_hz"] == 0.0
    assert (out["n_agents"] == 1).all() and out["sem_hz"].isna().all()  # one agent-episode: no SEM
    assert len(out) == 201 and out.loc[-100, "lag_ms"] == pytest.approx(-100 * STEP_MS)


def test_peri_event_rate_needs_enough_events():
    ate = np.zeros(300, bool)
    ate[[50, 150]] = True
    out = peri_event_rate(agent_steps(np.ones(300), ate=ate), "ate", fps=FPS)
    assert len(out) == 1 and np.isnan(out.loc[0, "mean_hz"]) and "3 or more 'ate' events" in out.loc[0, "reason"]
    with pytest.raises(ValueError, match="event must be one of"):
        peri_event_rate(agent_steps(np.ones(300)), "eaten", fps=FPS)


def test_rate_advantage_of_a_close_pair():
    on, off = np.ones(100), np.zeros(100)
    steps = pd.concat([agent_steps(on, size=0.8), agent_steps(off, agent=1, size=0.3, x_cm=15.0)])
    out = rate_advantage_vs_size(steps, fps=FPS)
    assert len(out) == 1 and out.loc[0, "size_advantage"] == pytest.approx(0.5)
    assert out.loc[0, "rate_advantage_hz"] == pytest.approx(83.0) and out.loc[0, "n_steps"] == 100 - 19
    far = rate_advantage_vs_size(steps.assign(x_cm=np.r_[np.full(100, 10.0), np.full(100, 90.0)]), fps=FPS)
    assert np.isnan(far.loc[0, "rate_advantage_hz"]) and "within 10.0 cm" in far.loc[0, "reason"]


def test_load_real_idis(tmp_path):
    missing = load_real_idis(None)
    assert np.isnan(missing.loc[0, "idi_ms"]) and "real_fish_idis is unset" in missing.loc[0, "reason"]
    assert "fewer than 10" in fit_power_law(missing["idi_ms"])["reason"]
    df = pd.DataFrame({"fish": [1, 1, 2], "idi_ms": [20.0, 35.5, 80.0]})
    df.to_csv(tmp_path / "idis.csv", index=False)
    df.to_parquet(tmp_path / "idis.parquet")
    for name in ("idis.csv", "idis.parquet"):
        assert load_real_idis(tmp_path / name)["idi_ms"].tolist() == [20.0, 35.5, 80.0]
    df.rename(columns={"idi_ms": "ms"}).to_csv(tmp_path / "bad.csv", index=False)
    with pytest.raises(ValueError, match="idi_ms"):
        load_real_idis(tmp_path / "bad.csv")
    with pytest.raises(FileNotFoundError):
        load_real_idis(tmp_path / "absent.csv")


def firing_after_events(agent=0, episode=0, fires=True, events=(200, 450, 700), t=1000) -> pd.DataFrame:
    """An agent-episode that eats at ``events`` and discharges on every step of the 40 after each (``fires``) or
    never."""
    ate, eod = np.zeros(t, bool), np.zeros(t, bool)
    for e in events:
        ate[e] = True
        eod[e:e + 40] = fires
    return agent_steps(eod, agent=agent, episode=episode, ate=ate)


def test_peri_event_episodes_is_the_change_of_the_agents_mean_rate():
    """Lags 15-25 after eating see a full window of discharges (83 Hz), lags -80 to -50 none: a change of 83 Hz
    for an agent that fires after eating and 0 for one that never does; episode 0 has both (41.5 Hz from 2
    agents), episode 1 the firing one alone; an agent-episode with 2 events (< 3) is left out."""
    steps = pd.concat([firing_after_events(), firing_after_events(agent=1, fires=False),
                       firing_after_events(episode=1), firing_after_events(agent=1, episode=1, events=(200, 450))])
    out = peri_event_episodes(steps, "ate", (15, 25), (-80, -50), fps=FPS)
    assert list(out.columns) == PERI_EPISODE_COLUMNS and (out["reason"] == "").all()
    assert out[["episode", "n_agents"]].values.tolist() == [[0, 2], [1, 1]]
    assert out["change_hz"].tolist() == pytest.approx([41.5, 83.0])
    assert out[["event", "event_lo", "event_hi", "baseline_lo", "baseline_hi"]].drop_duplicates().values.tolist() == [
        ["ate", 15, 25, -80, -50]]
    # the curves are peri_event_rate's: one agent-episode's change is the difference of its curve's window means
    noisy = firing_after_events().assign(eod=np.random.default_rng(2).random(1000) < 0.4)
    curve = peri_event_rate(noisy, "ate", fps=FPS).set_index("lag")["mean_hz"]
    (change,) = peri_event_episodes(noisy, "ate", (-10, 10), (-100, -50), fps=FPS)["change_hz"]
    assert change == pytest.approx(curve.loc[-10:10].mean() - curve.loc[-100:-50].mean(), abs=1e-12)


def test_peri_event_episodes_degenerate_and_errors():
    few = pd.concat([firing_after_events(events=(200, 450)), firing_after_events().assign(condition="d")])
    out = peri_event_episodes(few, "ate", fps={"c": FPS, "d": FPS})
    assert out["condition"].tolist() == ["c", "d"] and np.isnan(out.loc[0, "change_hz"])
    assert out.loc[0, "reason"] == "no agent-episode has 3 or more 'ate' events" and out.loc[0, "n_agents"] == 0
    beyond = peri_event_episodes(few, "ate", (-10, 10), (-150, -50), fps={"c": FPS, "d": FPS})
    assert beyond["change_hz"].isna().all() and len(beyond) == 2
    assert (beyond["reason"] == "the windows reach beyond analysis.peri_window = 100 steps").all()
    empty = peri_event_episodes(agent_steps([]), "bit", fps=FPS)
    assert len(empty) == 1 and empty.loc[0, "reason"] == "empty steps table"
    with pytest.raises(ValueError, match="event must be one of"):
        peri_event_episodes(few, "eaten", fps=FPS)
