"""Homing analyses: error angles over normalised time, and trajectory shape of scripted paths."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

from efish.analysis.homing import (
    ALIGNMENT_COLUMNS,
    alignment_episodes,
    compare_perception,
    error_angles,
    error_histogram,
    error_vs_time,
    trajectory_shape,
)


def path(x, y, heading=None, condition="electric", episode=0, agent=1, **columns) -> pd.DataFrame:
    x, y = np.asarray(x, dtype=float), np.asarray(y, dtype=float)
    heading = np.zeros_like(x) if heading is None else np.asarray(heading, dtype=float)
    return pd.DataFrame({"condition": condition, "episode": episode, "agent": agent, "t": np.arange(x.size),
                         "x_cm": x, "y_cm": y, "heading_rad": heading, **columns})


def test_error_angles_long_table_and_normalised_time():
    steps = path(np.arange(5.0), np.zeros(5), err_morm_rad=[0.1, 0.2, np.nan, 0.4, 7.0],
                 err_amp_rad=np.nan, err_knollen_rad=-0.5)
    long = error_angles(steps)
    morm = long[long["channel"] == "morm"]
    assert morm["t_norm"].tolist() == [0.0, 0.25, 0.75, 1.0]       # the NaN step is left out
    assert morm["err_rad"].iloc[-1] == pytest.approx(7.0 - 2 * np.pi)  # wrapped to [-pi, pi)
    assert set(long["channel"]) == {"morm", "knollen"}
    with pytest.raises(ValueError, match="error-angle column"):
        error_angles(path([0.0], [0.0]))


def test_alignment_per_agent_episode_against_a_straight_homer():
    """Episode 0: 8 of 10 Knollenorgan errors within pi/4 of 0 or pi, a straight homer (error + bearing) aligned on
    none, |sin err| falling over time; episode 1: none aligned, a straight homer on every step, |sin err| constant
    (no rho); episode 2: episode 0's errors with the bearing 0 (a straight homer as aligned as the homer), no
    success. The frozen target (agent 0) senses nothing: no row."""
    err = np.r_[1.5, 1.4, np.linspace(0.7, 0.05, 7), np.pi - 0.02]  # 8 within pi/4 of 0 or pi, |sin| falling
    ep0 = path(np.arange(10.0), np.zeros(10), err_knollen_rad=err, bearing_agent_rad=np.pi / 2 - err,
               success=np.arange(10) == 9)
    ep1 = path(np.arange(10.0), np.zeros(10), episode=1, err_knollen_rad=np.pi / 2,
               bearing_agent_rad=-np.pi / 2, success=np.arange(10) == 9)
    ep2 = path(np.arange(10.0), np.zeros(10), episode=2, err_knollen_rad=err, bearing_agent_rad=0.0, success=False)
    target = path(np.zeros(10), np.zeros(10), agent=0, err_knollen_rad=np.nan, bearing_agent_rad=0.0, success=False)
    out = alignment_episodes(pd.concat([ep0, ep1, ep2, target], ignore_index=True))
    assert list(out.columns) == ALIGNMENT_COLUMNS
    assert out[["episode", "agent", "channel"]].to_numpy().tolist() == [[0, 1, "knollen"], [1, 1, "knollen"],
                                                                       [2, 1, "knollen"]]
    assert out["success"].tolist() == [True, True, False] and (out["n_steps"] == 10).all()
    assert out["aligned_fraction"].tolist() == pytest.approx([0.8, 0.0, 0.8])
    assert out["straight_aligned_fraction"].tolist() == pytest.approx([0.0, 1.0, 0.8])
    assert out["aligned_excess"].tolist() == pytest.approx([0.8, -1.0, 0.0])
    assert out.loc[0, "alignment_rho"] == pytest.approx(-1.0) and out.loc[0, "reason"] == ""
    assert np.isnan(out.loc[1, "alignment_rho"]) and out.loc[1, "reason"] == "abs_sin is constant"
    wide = alignment_episodes(ep0, aligned_rad=np.pi / 2)  # every step within pi/2 of 0 or pi
    assert wide.loc[0, "aligned_fraction"] == 1.0


def test_error_histogram_density_integrates_to_one():
    rng = np.random.default_rng(0)
    h = error_histogram(path(np.zeros(300), np.zeros(300), err_morm_rad=rng.vonmises(0.0, 2.0, 300)))
    assert len(h) == 36 and h["count"].sum() == 300
    assert np.sum(h["density"] * (h["bin_hi_rad"] - h["bin_lo_rad"])) == pytest.approx(1.0)
    peak = h.loc[h["count"].idxmax()]
    assert abs(peak["bin_lo_rad"] + peak["bin_hi_rad"]) / 2 < np.pi / 6  # peaks near zero error


def test_error_vs_time_of_a_shrinking_error():
    err = np.linspace(-1.0, 0.0, 100)  # error shrinks linearly to 0 over the episode
    out = error_vs_time(path(np.zeros(100), np.zeros(100), err_morm_rad=err), bins=4)
    assert out["n"].tolist() == [25, 25, 25, 25]
    assert np.all(np.diff(out["mean_abs_err_rad"]) < 0) and (out["circmean_err_rad"] < 0).all()
    assert out["t_norm_mid"].tolist() == [0.125, 0.375, 0.625, 0.875]


def test_straight_and_bent_paths():
    straight = path(np.arange(11.0), np.zeros(11))
    bent = path(np.r_[np.arange(6.0), np.full(5, 5.0)], np.r_[np.zeros(6), np.arange(1.0, 6.0)],
                heading=np.r_[np.zeros(5), np.full(6, np.pi / 2)], episode=1)
    frozen = path(np.zeros(5), np.zeros(5), agent=0)
    shape = trajectory_shape(pd.concat([straight, bent, frozen])).set_index(["episode", "agent"])
    assert shape.loc[(0, 1), "tortuosity"] == pytest.approx(1.0)
    assert shape.loc[(0, 1), "curvature_rad_per_cm"] == 0.0
    assert shape.loc[(1, 1), "tortuosity"] == pytest.approx(10 / np.hypot(5, 5))
    assert shape.loc[(1, 1), "curvature_rad_per_cm"] == pytest.approx((np.pi / 2) / 10)
    assert np.isnan(shape.loc[(0, 0), "tortuosity"]) and shape.loc[(0, 0), "reason"] == "agent did not move"
    loop = trajectory_shape(path([0.0, 1.0, 1.0, 0.0], [0.0, 0.0, 1.0, 0.0]))
    assert np.isnan(loop.loc[0, "tortuosity"]) and loop.loc[0, "reason"] == "start and end coincide"


def test_compare_perception_rows():
    rng = np.random.default_rng(0)
    parts = []
    for cond, wiggle in (("electric", 0.1), ("raycasting", 2.0)):
        for e in range(8):
            parts.append(path(np.arange(20.0), rng.normal(0, wiggle, 20), condition=cond, episode=e,
                              success=np.arange(20) == 19))
    out = compare_perception(pd.concat(parts), agent=1).set_index("measure")
    assert out.loc["tortuosity", "group"] == "raycasting" and out.loc["tortuosity", "n"] == 8
    assert out.loc["tortuosity", "effect"] > 0 and out.loc["tortuosity", "p"] < 0.01
    assert out.loc["n_steps", "reason"] == "all values identical"
    assert trajectory_shape(pd.concat(parts))["success"].all()
    with pytest.raises(ValueError, match="'rays'"):
        compare_perception(pd.concat(parts), raycasting="rays")


def test_missing_positions_and_angles_say_why():
    shape = trajectory_shape(path([0.0, np.nan, 2.0], [0.0, 0.0, 0.0]))
    assert np.isnan(shape.loc[0, "tortuosity"]) and shape.loc[0, "reason"] == "missing position or heading"
    no_angles = path(np.arange(3.0), np.zeros(3), err_morm_rad=np.nan)
    assert error_histogram(no_angles).loc[0, "reason"] == "no finite error angle"
    assert error_vs_time(no_angles).loc[0, "reason"] == "no finite error angle"
