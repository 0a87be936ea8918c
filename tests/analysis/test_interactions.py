"""Interaction labels and bouts on scripted geometries give the scripted labels and boundaries."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

from efish.analysis.interactions import (
    LABELS,
    bite_rate_by_class,
    bite_sizes,
    bite_timing,
    bouts,
    chase_sizes,
    label_steps,
)

PI = np.pi


def two_fish(x1, h0, h1, y1=None, bites0=None, sizes=(0.8, 0.3)) -> pd.DataFrame:
    """Agent 0 at the origin heading h0, agent 1 at (x1, y1) heading h1; one row per step and agent."""
    x1, h0, h1 = (np.broadcast_to(np.asarray(v, dtype=float), np.shape(x1)) for v in (x1, h0, h1))
    n = len(x1)
    y1 = np.zeros(n) if y1 is None else np.asarray(y1, dtype=float)
    bites0 = np.full(n, -1) if bites0 is None else np.asarray(bites0)
    frames = [pd.DataFrame({"agent": 0, "x_cm": 0.0, "y_cm": 0.0, "heading_rad": h0, "bite_target": bites0,
                            "size": sizes[0]}),
              pd.DataFrame({"agent": 1, "x_cm": x1, "y_cm": y1, "heading_rad": h1, "bite_target": -1,
                            "size": sizes[1]})]
    return pd.concat([f.assign(condition="c", episode=0, t=np.arange(n)) for f in frames], ignore_index=True)


# (heading of 0, heading of 1, label of 0 towards 1, label of 1 towards 0); agent 1 is 5 cm along +x
GEOMETRIES = [(0.0, PI, "confronting", "confronting"),
              (0.0, 0.0, "chasing", "fleeing"),
              (PI, PI, "fleeing", "chasing"),
              (PI, 0.0, "dispersing", "dispersing"),
              (PI / 2, PI, "unaligned", "unaligned"),          # 1 faces 0, 0 looks sideways
              (0.3, PI - 0.3, "confronting", "confronting"),  # inside the pi/4 cone
              (0.0, PI / 2 + 0.1, "unaligned", "unaligned")]   # 0 faces 1, 1 looks sideways


@pytest.mark.parametrize(("h0", "h1", "label0", "label1"), GEOMETRIES)
def test_scripted_labels(h0, h1, label0, label1):
    out = label_steps(two_fish([5.0], h0, h1)).set_index("agent")
    assert out.loc[0, "label"] == label0 and out.loc[1, "label"] == label1
    assert out.loc[0, "partner"] == 1 and out.loc[0, "dist_cm"] == pytest.approx(5.0)


def test_labels_use_the_bearing_not_the_axis():
    # agent 1 straight above agent 0 (bearing +pi/2); 0 heads up, 1 heads up too: 0 chases 1
    out = label_steps(two_fish([0.0], PI / 2, PI / 2, y1=[7.0])).set_index("agent")
    assert out.loc[0, "label"] == "chasing" and out.loc[1, "label"] == "fleeing"


def test_label_steps_needs_only_positions_and_headings():
    steps = two_fish([5.0, 50.0], 0.0, 0.0)[["condition", "episode", "t", "agent", "x_cm", "y_cm", "heading_rad"]]
    out = label_steps(steps, within_cm=10)
    assert out["t"].tolist() == [0, 0] and set(out.columns) >= {"partner", "label"}
    assert set(label_steps(steps)["label"]) <= set(LABELS)
    with pytest.raises(ValueError, match="heading_rad"):
        label_steps(steps.drop(columns="heading_rad"))


def test_coincident_agents_and_missing_headings_are_undefined_not_guessed():
    assert (label_steps(two_fish([0.0], 0.0, 0.0))["label"] == "undefined").all()
    assert (label_steps(two_fish([5.0], np.nan, 0.0))["label"] == "undefined").all()


def test_bout_boundaries_and_classes():
    #         t: 0   1   2   3   4   5   6   7   8   9  10  11
    x1 = np.array([30, 8, 6, 5, 9, 40, 40, 10, 2, 3, 50, 4.0])
    h1 = np.r_[np.zeros(5), np.full(7, PI)]          # 1 flees 0 while t < 5, then turns to face 0
    bites0 = np.where(np.isin(np.arange(12), [3, 8]), 1, -1)
    b = bouts(two_fish(x1, 0.0, h1, bites0=bites0))
    assert b[["t_start", "t_end", "n_steps"]].to_numpy().tolist() == [[1, 4, 4], [7, 9, 3], [11, 11, 1]]
    assert b["label"].tolist() == ["chasing", "confronting", "confronting"]
    assert b["chaser"].tolist() == [0, -1, -1] and b["chased"].tolist() == [1, -1, -1]
    assert b["aggressive"].tolist() == [True, True, False] and b["bites_by_agent"].tolist() == [1, 1, 0]
    assert b["contact"].tolist() == [False, True, False] and b["min_dist_cm"].tolist() == [5.0, 2.0, 4.0]
    reduced = bouts(two_fish(x1, 0.0, h1, bites0=bites0), within_cm=5)
    assert reduced[["t_start", "t_end"]].to_numpy().tolist() == [[3, 3], [8, 9], [11, 11]]


def test_a_gap_in_time_ends_a_bout():
    steps = two_fish(np.full(6, 5.0), 0.0, PI)
    steps = steps[steps["t"] != 3]  # a missing step (e.g. a dropped row) breaks the run
    assert bouts(steps)[["t_start", "t_end"]].to_numpy().tolist() == [[0, 2], [4, 5]]


def test_chaser_and_biter_sizes():
    steps = two_fish(np.full(5, 5.0), PI, PI, bites0=[-1, -1, -1, -1, -1], sizes=(0.3, 0.8))  # 1 chases 0
    steps.loc[(steps["agent"] == 1) & (steps["t"] == 2), "bite_target"] = 0
    chases = chase_sizes(steps)
    assert chases[["chaser", "chased"]].to_numpy().tolist() == [[1, 0]]
    assert chases.loc[0, "size_difference"] == pytest.approx(0.5)
    bites = bite_sizes(steps)
    assert bites[["biter", "bitten", "t"]].to_numpy().tolist() == [[1, 0, 2]]
    assert bites.loc[0, "biter_size"] == pytest.approx(0.8)


def test_bite_timing_within_bouts():
    bites0 = np.where(np.arange(6) == 4, 1, -1)
    timing = bite_timing(two_fish(np.r_[40.0, np.full(5, 5.0)], 0.0, 0.0, bites0=bites0))
    assert timing[["t", "t_from_start", "n_steps"]].to_numpy().tolist() == [[4, 3, 5]]
    assert timing.loc[0, "phase"] == pytest.approx(3.5 / 5) and timing.loc[0, "label"] == "chasing"


def test_bite_rate_by_class():
    bites0 = np.where(np.arange(4) == 1, 1, -1)
    out = bite_rate_by_class(two_fish(np.full(4, 5.0), 0.0, 0.0, bites0=bites0)).set_index("label")
    assert out.loc["chasing", "n_steps"] == 4 and out.loc["chasing", "rate"] == 0.25
    assert out.loc["fleeing", "rate"] == 0.0 and np.isnan(out.loc["confronting", "rate"])
    far = bite_rate_by_class(two_fish(np.full(4, 50.0), 0.0, 0.0))
    assert len(far) == 1 and "within 10.0 cm" in far.loc[0, "reason"]


def test_bite_rate_per_episode_is_each_episodes_own_and_pools_to_the_condition():
    """Episode 0: 4 chasing pair-steps (and their 4 fleeing mirrors), 1 bite; episode 1: 3 confronting steps (6
    ordered pair-steps, 2 bites) and 5 steps out of range; episode 2: never within range (no rows)."""
    chase = two_fish(np.full(4, 5.0), 0.0, 0.0, bites0=np.where(np.arange(4) == 1, 1, -1))
    confront = two_fish(np.r_[np.full(3, 5.0), np.full(5, 50.0)], 0.0, PI, bites0=np.r_[1, -1, 1, np.full(5, -1)])
    apart = two_fish(np.full(4, 50.0), 0.0, 0.0)
    steps = pd.concat([chase, confront.assign(episode=1), apart.assign(episode=2)], ignore_index=True)
    out = bite_rate_by_class(steps, by=("condition", "episode"))
    assert len(out) == 2 * len(LABELS) and out["episode"].unique().tolist() == [0, 1]
    rate = out.set_index(["episode", "label"])
    assert (rate.loc[(0, "chasing"), "n_steps"], rate.loc[(0, "chasing"), "bites"]) == (4, 1)
    assert rate.loc[(0, "chasing"), "rate"] == 0.25 and np.isnan(rate.loc[(0, "confronting"), "rate"])
    assert (rate.loc[(1, "confronting"), "n_steps"], rate.loc[(1, "confronting"), "rate"]) == (6, pytest.approx(1 / 3))
    assert rate.loc[(1, "chasing"), "reason"] == "label never seen within range"
    pooled = bite_rate_by_class(steps).set_index("label")
    summed = out.groupby("label")[["n_steps", "bites"]].sum()
    assert pooled[["n_steps", "bites"]].equals(summed.loc[pooled.index])
    far = bite_rate_by_class(apart, by=("condition", "episode"))
    assert len(far) == 1 and np.isnan(far.loc[0, "episode"]) and "within 10.0 cm" in far.loc[0, "reason"]


def test_empty_steps_give_empty_bouts_not_errors():
    empty = two_fish(np.empty(0), 0.0, 0.0)
    assert bouts(empty).empty and chase_sizes(empty).empty and bite_timing(empty).empty
