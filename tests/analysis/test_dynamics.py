"""Hidden-state analyses with planted answers; every analysis module imports without numba or torch."""

from __future__ import annotations

import subprocess
import sys

import numpy as np
import pandas as pd
import pytest

from efish.analysis.dynamics import (
    degenerate_reason,
    dynamics_table,
    effective_dimensionality,
    hidden_matrix,
    pca_variances,
    pcs_for_variance,
    plsc,
    plsc_by_distance,
    plsc_episodes,
    subsample_units,
    wideband_power,
)

MODULES = ["signalling", "behaviour", "interactions", "homing", "stats", "dynamics", "decoding"]
FPS = 83.0  # steps per second (env.fps's default)


def test_analysis_modules_load_neither_numba_nor_torch():
    # one fresh interpreter for all: if their union loads neither, none of them does
    code = (f"import sys; import {', '.join('efish.analysis.' + m for m in MODULES)}; "
            "bad = [m for m in ('numba', 'torch') if m in sys.modules]; assert not bad, bad")
    subprocess.run([sys.executable, "-c", code], check=True)


def test_effective_dimensionality_of_isotropic_and_rank_one_data():
    rng = np.random.default_rng(0)
    assert effective_dimensionality(rng.normal(size=(4000, 8))) == pytest.approx(8.0, rel=0.02)
    rank1 = np.outer(rng.normal(size=200), rng.normal(size=16))
    assert effective_dimensionality(rank1) == pytest.approx(1.0)
    assert pcs_for_variance(rank1) == 1.0


def test_pcs_for_variance_on_a_known_spectrum():
    rng = np.random.default_rng(0)
    z = rng.normal(size=(500, 4))
    z = np.linalg.qr(z - z.mean(axis=0))[0]          # orthonormal columns with zero mean
    h = z * np.sqrt([0.6, 0.25, 0.1, 0.05])          # variances 0.6, 0.25, 0.1, 0.05 of the total
    np.testing.assert_allclose(pca_variances(h), [0.6, 0.25, 0.1, 0.05], atol=1e-9)
    assert [pcs_for_variance(h, f) for f in (0.5, 0.85, 0.9, 0.95, 1.0)] == [1, 2, 3, 3, 4]


@pytest.mark.parametrize(("h", "reason"), [(np.ones((50, 4)), "no unit varies"),
                                           (np.c_[np.arange(50.0), np.full(50, np.nan)], "non-finite values"),
                                           (np.ones((1, 4)), "need a T x D matrix")])
def test_degenerate_hidden_states_give_nan_with_a_reason(h, reason):
    assert degenerate_reason(h).startswith(reason)
    assert np.isnan(effective_dimensionality(h)) and np.isnan(pcs_for_variance(h))
    assert np.isnan(wideband_power(h, fs=FPS))


def test_constant_units_do_not_count():
    rng = np.random.default_rng(0)
    h = np.c_[rng.normal(size=(3000, 3)), np.full((3000, 5), 2.0)]
    assert effective_dimensionality(h) == pytest.approx(3.0, rel=0.03)


def test_subsample_units():
    rng = np.random.default_rng(0)
    h = rng.normal(size=(300, 40))
    out = subsample_units(h, draws=4, rng=1)
    assert out.groupby("fraction")["n_units"].first().tolist() == [2, 6, 10, 20, 30, 40]
    assert len(out) == 24 and out.groupby("fraction")["d_eff"].mean().is_monotonic_increasing
    full = out[out["fraction"] == 1.0]["d_eff"]
    assert full.to_numpy() == pytest.approx(np.full(4, effective_dimensionality(h)))
    assert out.equals(subsample_units(h, draws=4, rng=1))


def test_plsc_finds_planted_shared_dimensions():
    rng = np.random.default_rng(0)
    t, k = 800, 3
    shared = rng.normal(size=(t, k))
    h_a = shared @ rng.normal(size=(k, 16)) + rng.normal(size=(t, 16))
    h_b = shared @ rng.normal(size=(k, 12)) + rng.normal(size=(t, 12))
    out = plsc(h_a, h_b, rng=0)
    assert out["n_significant"] == k and len(out["singular_values"]) == 12
    assert np.all(np.diff(out["singular_values"]) <= 0)
    independent = plsc(rng.normal(size=(t, 16)), rng.normal(size=(t, 12)), rng=0)
    assert independent["n_significant"] == 0


def test_plsc_degenerate():
    rng = np.random.default_rng(0)
    out = plsc(np.ones((100, 4)), rng.normal(size=(100, 4)), rng=0)
    assert np.isnan(out["n_significant"]) and out["reason"] == "no unit varies"
    with pytest.raises(ValueError, match="differ in length"):
        plsc(rng.normal(size=(100, 4)), rng.normal(size=(90, 4)))


def test_wideband_power_scales_with_variance_and_is_per_hz_of_the_step_rate():
    rng = np.random.default_rng(0)
    h = rng.normal(size=(400, 6))
    assert wideband_power(2 * h, fs=FPS) == pytest.approx(4 * wideband_power(h, fs=FPS))
    assert wideband_power(h, fs=FPS / 2) == pytest.approx(2 * wideband_power(h, fs=FPS))  # a density per Hz
    assert np.isnan(wideband_power(h[:19], fs=FPS))  # shorter than one 20-step window


def test_hidden_frame_helpers():
    rng = np.random.default_rng(0)
    rows = []
    for agent in (0, 1):
        h = rng.normal(size=(60, 12)) if agent == 0 else np.zeros((60, 12))
        frame = pd.DataFrame(h, columns=[f"h_{i}" for i in range(12)])
        rows.append(frame.assign(condition="c", episode=0, t=np.arange(60), agent=agent))
    hidden = pd.concat(rows, ignore_index=True)
    shuffled = hidden.sample(frac=1.0, random_state=0)
    mine = hidden_matrix(shuffled[shuffled["agent"] == 0])
    np.testing.assert_array_equal(mine, hidden[hidden["agent"] == 0][[f"h_{i}" for i in range(12)]].to_numpy())
    table = dynamics_table(shuffled, fps=FPS).set_index("agent")
    assert table.loc[0, "d_eff"] > 5 and table.loc[0, "reason"] == ""
    assert np.isnan(table.loc[1, "d_eff"]) and table.loc[1, "reason"] == "no unit varies"
    with pytest.raises(ValueError, match="h_<i>"):
        hidden_matrix(hidden[["t", "agent"]])


def test_plsc_by_distance_finds_sharing_only_where_planted():
    rng = np.random.default_rng(0)
    t = 900
    dist = np.repeat([5.0, 50.0, 500.0], t // 3)  # close, mid and far thirds of the episode
    shared = rng.normal(size=(t, 2)) * (dist == 5.0)[:, None]  # the agents share 2 dimensions only when close
    h_a = shared @ rng.normal(size=(2, 10)) + rng.normal(size=(t, 10))
    h_b = shared @ rng.normal(size=(2, 8)) + rng.normal(size=(t, 8))
    out = plsc_by_distance(h_a, h_b, dist, rng=0)
    assert out["n_significant"].tolist() == [2, 0, 0] and out["n_steps"].tolist() == [300, 300, 300]
    assert out["hi_cm"].tolist() == [10.0, 100.0, np.inf] and (out["reason"] == "").all()
    sparse = plsc_by_distance(h_a[:20], h_b[:20], np.full(20, 500.0), rng=0)
    assert sparse.loc[0, "reason"].startswith("need a T x D") and np.isnan(sparse.loc[0, "n_significant"])


def test_plsc_episodes_gives_each_episodes_first_component_per_distance_bin():
    """Two episodes, each 30 steps 5 cm apart, 30 at 50 cm, 5 at 500 cm: the agents share their states only when
    close, so r_1 is 1 in the first bin; the third bin has too few steps. Agent 2 is left out."""
    rng = np.random.default_rng(0)
    dist = np.r_[np.full(30, 5.0), np.full(30, 50.0), np.full(5, 500.0)]
    t, units = np.arange(len(dist)), [f"h_{i}" for i in range(4)]
    hidden, steps = [], []
    for episode in (0, 1):
        own = rng.normal(size=(len(t), 4))
        for agent in (0, 1, 2):
            h = np.where((dist == 5.0)[:, None] | (agent == 0), own, rng.normal(size=(len(t), 4)))
            hidden.append(pd.DataFrame(h, columns=units).assign(condition="c", episode=episode, agent=agent, t=t))
            steps.append(pd.DataFrame({"condition": "c", "episode": episode, "agent": agent, "t": t,
                                       "x_cm": dist * (agent == 1), "y_cm": 0.0}))
    hidden, steps = pd.concat(hidden, ignore_index=True), pd.concat(steps, ignore_index=True)
    out = plsc_episodes(hidden.sample(frac=1.0, random_state=0), steps)
    assert out[["episode", "bin", "n_steps"]].to_numpy().tolist() == [[e, b, n] for e in (0, 1)
                                                                      for b, n in enumerate((30, 30, 5))]
    assert (out["agent_a"] == 0).all() and (out["agent_b"] == 1).all()
    assert out["hi_cm"].tolist() == [10.0, 100.0, np.inf] * 2 and out["lo_cm"].tolist() == [0.0, 10.0, 100.0] * 2
    close, mid, far = (out[out["bin"] == b] for b in range(3))
    assert close["r_1"].to_numpy() == pytest.approx(1.0) and (mid["r_1"] < close["r_1"].to_numpy()).all()
    assert far["r_1"].isna().all() and far["reason"].str.startswith("need a T x D").all()
    # the first component of plsc on the same steps (the paper's procedure, without its null)
    mine = hidden.sort_values(["agent", "t"], kind="stable").query("episode == 1 and t >= 30 and t < 60")
    ref = plsc(mine[mine["agent"] == 0][units], mine[mine["agent"] == 1][units], shifts=1, rng=0)
    assert mid["r_1"].iloc[1] == pytest.approx(ref["correlations"][0], rel=1e-12)
    assert mid["s_1"].iloc[1] == pytest.approx(ref["singular_values"][0], rel=1e-12)
    alone = plsc_episodes(hidden, steps, agents=(0, 3))
    assert len(alone) == 1 and alone.loc[0, "reason"] == "agents 0 and 3 share no step"


def test_d_eff_by_the_gram_matrix_is_the_svds_and_a_subsets_block_is_its_own():
    """trace(G)^2 / ||G||_F^2 equals 1 / sum(lambda^2) of the SVD's normalised variances; a draw of units, read
    from the whole Gram matrix's block, equals D_eff of those columns alone, degenerate draws included."""
    rng = np.random.default_rng(3)
    h = rng.normal(size=(500, 6)) @ rng.normal(size=(6, 12)) + 0.1 * rng.normal(size=(500, 12))
    assert effective_dimensionality(h) == pytest.approx(1.0 / np.sum(pca_variances(h) ** 2), rel=1e-12)
    h[:, 3] = 2.0  # a constant unit
    h[7, 5] = np.nan  # a unit with a non-finite value
    out = subsample_units(h, fractions=(0.05, 0.25, 0.5), draws=20, rng=4)
    again = np.random.default_rng(4)
    for _, row in out.iterrows():
        k = row["n_units"]
        sub = h[:, again.choice(h.shape[1], size=k, replace=False)]
        assert row["reason"] == degenerate_reason(sub)
        expected = effective_dimensionality(sub)
        assert (np.isnan(row["d_eff"]) and np.isnan(expected)) or row["d_eff"] == pytest.approx(expected, rel=1e-12)
    assert set(out["reason"]) >= {"", "non-finite values", "no unit varies"}
