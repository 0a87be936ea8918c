"""Calibrated PLSC tests with known answers: false-positive rates on independent autocorrelated series, the collapse
test on planted sharing (docs/methods/analyses.md#analysis-dynamics, claim C20).

Rates are checked against a binomial bound: with ``n`` datasets and a true rate
of 0.05, more than :func:`bound` false positives happen with probability below
0.001, so a count above it says the rate exceeds the nominal level (and the
check itself fails by chance once in a thousand seeds at most; the seeds are
fixed, so it is deterministic).
"""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest
from scipy import signal, stats

from efish.analysis.dynamics import COLLAPSE_COLUMNS, plsc, plsc_collapse_table, plsc_table
from efish.analysis.plsc_tests import plsc_collapse, shared_dimensions

ALPHA = 0.05


def bound(n: int, rate: float = ALPHA) -> int:
    """The most false positives out of ``n`` that a true ``rate`` exceeds with probability below 0.001."""
    return int(stats.binom.ppf(0.999, n, rate))


def ar1(rng: np.random.Generator, n: int, d: int, phi: float) -> np.ndarray:
    """n steps of d independent stationary AR(1) series with coefficient phi (unit innovations)."""
    e = rng.normal(size=(n, d))
    e[0] /= np.sqrt(1 - phi ** 2)  # a stationary start: the first value has the process's variance
    return signal.lfilter([1.0], [1.0, -phi], e, axis=0)


def pair(rng: np.random.Generator, lengths, d: int, phi: float, k: int = 0,
         strength: float = 0.0) -> tuple[list[np.ndarray], list[np.ndarray]]:
    """Two agents' blocks, one per episode of the given ``lengths``: independent AR(1) states, plus ``k`` shared
    latent AR(1) dimensions times ``strength`` added to the first k units of both (none when k is 0)."""
    a, b = [], []
    for n in lengths:
        xa, xb = ar1(rng, n, d, phi), ar1(rng, n, d, phi)
        if k:
            z = strength * ar1(rng, n, k, phi)
            xa[:, :k] += z
            xb[:, :k] += z
        a.append(xa)
        b.append(xb)
    return a, b


def old_count(a: list[np.ndarray], b: list[np.ndarray], seed: int) -> int:
    """The paper's procedure (:func:`efish.analysis.dynamics.plsc`) on the concatenated blocks."""
    return plsc(np.concatenate(a), np.concatenate(b), rng=seed)["n_significant"]


# ------------------------------------------------------------ calibration
def test_the_count_is_calibrated_on_independent_autocorrelated_states_where_the_paper_null_is_not():
    """No shared dimension; 8 episodes of 50-150 steps, 16 units, AR(1) phi 0.99 (slow, like a recurrent state):
    the family-wise rate of counting >= 1 dimension. Measured with these seeds: 8 of 200 (4%) for the
    episode-swap step-down count, 83 of 200 (41.5%) for the paper's circular-shift null."""
    n, new, old = 200, 0, 0
    for seed in range(n):
        rng = np.random.default_rng(seed)
        a, b = pair(rng, rng.integers(50, 150, 8), 16, 0.99)
        new += shared_dimensions(a, b, draws=99, alpha=ALPHA, rng=seed)["n_significant"] > 0
        old += old_count(a, b, seed) > 0
    assert new <= bound(n), f"episode-swap count: {new} of {n} false positives"
    assert old > bound(n), f"the paper's null was expected to be lenient here: {old} of {n}"


def test_the_count_does_not_run_on_past_the_planted_dimensions():
    """Two shared dimensions, strong; 8 episodes of 100-200 steps, 16 units, phi 0.9: counting more than 2 is a
    false positive. The paper's procedure compares the 3rd observed singular value (the largest of the noise)
    with the null's 3rd and counts on; the step-down test compares it with the null's largest. Measured: 4 of 100
    above 2 (2 found in 92) against the paper's 46 of 100."""
    n, new, old, found = 100, 0, 0, 0
    for seed in range(n):
        rng = np.random.default_rng(seed)
        a, b = pair(rng, rng.integers(100, 200, 8), 16, 0.9, k=2, strength=2.0)
        count = shared_dimensions(a, b, draws=99, alpha=ALPHA, rng=seed)["n_significant"]
        new, found = new + (count > 2), found + (count == 2)
        old += old_count(a, b, seed) > 2
    assert new <= bound(n), f"step-down count: {new} of {n} above the planted 2"
    assert old > bound(n), f"the paper's count was expected to overshoot: {old} of {n}"
    assert found >= 0.9 * n, f"the planted 2 dimensions found in {found} of {n}"


def test_shared_dimensions_reports_p_values_step_down_and_says_why_it_cannot_run():
    rng = np.random.default_rng(0)
    a, b = pair(rng, [300] * 6, 8, 0.5, k=1, strength=3.0)
    out = shared_dimensions(a, b, draws=49, rng=0)
    assert out["n_significant"] == 1 and out["n_episodes"] == 6 and out["n_steps"] == 1800
    p = out["p_values"]
    assert p[0] == pytest.approx(1 / 50) and p[1] >= ALPHA and np.isnan(p[2:]).all()
    assert np.all(np.diff(out["singular_values"]) <= 0)
    assert shared_dimensions(a[:1], b[:1])["reason"].startswith("fewer than 2 episodes")
    assert np.isnan(shared_dimensions(a[:1], b[:1])["n_significant"])
    with pytest.raises(ValueError, match="differ in length"):
        shared_dimensions(a, [x[:-1] for x in b])


def test_few_episodes_cannot_give_a_small_p():
    """With 3 episodes, one permutation in 6 is the observed pairing: p cannot fall far below 1/6."""
    rng = np.random.default_rng(0)
    a, b = pair(rng, [300] * 3, 8, 0.5, k=2, strength=3.0)
    out = shared_dimensions(a, b, draws=199, rng=0)
    assert out["n_significant"] == 0 and out["p_values"][0] > 0.1


# ------------------------------------------------------------- collapse
def collapse(seed: int, k_near: int, k_far: int, strength: float = 5.0, **kw) -> dict:
    """The collapse test on 8 episodes: near 400-600 steps each (about 4,000), far 60-120 (about 700), 16 units,
    phi 0.9, ``k_near`` and ``k_far`` shared dimensions."""
    rng = np.random.default_rng(seed)
    near = pair(rng, rng.integers(400, 600, 8), 16, 0.9, k_near, strength)
    far = pair(rng, rng.integers(60, 120, 8), 16, 0.9, k_far, strength)
    return plsc_collapse(*near, *far, **{"draws": 49, "rng": seed, **kw})


@pytest.mark.parametrize("seed", [0, 1])
def test_collapse_is_significant_when_only_near_pairs_share(seed):
    out = collapse(seed, 3, 0)
    assert out["effect"] < 0 and out["p"] < ALPHA and out["p_less"] < ALPHA
    assert out["near_significant"] >= 2 and out["far_significant"] == 0 and out["count_difference"] < 0
    assert out["exact"] and out["n_assignments"] == 256 and out["n_episodes"] == 8


def test_collapse_in_the_opposite_direction_is_not_the_papers():
    out = collapse(0, 0, 3)
    assert out["effect"] > 0 and out["p_less"] > 0.5 and out["p"] < ALPHA


def test_collapse_is_not_called_at_the_nominal_rate_without_sharing_and_with_unequal_bins():
    """No sharing in either bin (near ~4,000 steps, far ~700): the two-sided p < 0.05 no more often than a 5% test
    may. Smaller than the other tests (6 episodes, 8 units, 1 window) to keep it fast."""
    n, hits = 40, 0
    for seed in range(n):
        rng = np.random.default_rng(seed)
        near = pair(rng, rng.integers(400, 600, 6), 8, 0.9)
        far = pair(rng, rng.integers(60, 120, 6), 8, 0.9)
        hits += plsc_collapse(*near, *far, draws=19, rng=seed)["p"] < ALPHA
    assert hits <= bound(n), f"{hits} of {n} significant"


def test_equal_sharing_in_unequal_bins_is_no_collapse_although_the_papers_counts_fall():
    """Both bins share 3 dimensions; near has ~6 times the steps. The paper's counts are larger near (the
    criterion far - near < 0 'holds'); at equal size the test does not find fewer far."""
    n, new, old = 12, 0, 0
    for seed in range(n):
        out = collapse(seed, 3, 3, strength=2.0)
        new += (out["p"] < ALPHA) and out["effect"] < 0
        rng = np.random.default_rng(seed)
        near = pair(rng, rng.integers(400, 600, 8), 16, 0.9, 3, 2.0)
        far = pair(rng, rng.integers(60, 120, 8), 16, 0.9, 3, 2.0)
        old += old_count(*far, seed) < old_count(*near, seed)
    assert new <= 2 and old >= n // 2, (new, old)


def test_several_windows_combine_as_twice_the_median_p():
    """Each window is an exact test; twice their median p is a p whatever their dependence."""
    one, three = collapse(0, 3, 0), collapse(0, 3, 0, windows=3)
    assert three["effect"] < 0 and three["p"] >= 2 * 2 / 256 and three["p"] >= one["p"]
    assert three["n_steps"] == one["n_steps"] and three["far_significant"] == 0


def test_collapse_says_why_it_cannot_run():
    rng = np.random.default_rng(0)
    near = pair(rng, [200, 200], 4, 0.5)
    far = pair(rng, [5, 200], 4, 0.5)  # episode 0 has too few far steps: one unit is left
    out = plsc_collapse(*near, *far, draws=9)
    assert np.isnan(out["p"]) and out["n_episodes"] == 1 and "fewer than 2 episodes" in out["reason"]
    with pytest.raises(ValueError, match="one entry per episode"):
        plsc_collapse(*near, far[0][:1], far[1])


# ---------------------------------------------------------------- tables
def hidden_and_steps(seed: int = 0, episodes: int = 6, d: int = 8) -> tuple[pd.DataFrame, pd.DataFrame]:
    """Two agents over ``episodes`` of 300 steps: 60 far apart (150 cm), 120 at middle distance, 120 close (5 cm);
    their states share 2 dimensions only when close."""
    rng = np.random.default_rng(seed)
    dist = np.repeat([150.0, 50.0, 5.0], [60, 120, 120])
    hidden, steps = [], []
    for e in range(episodes):
        (a,), (b,) = pair(rng, [300], d, 0.8)
        z = 3.0 * ar1(rng, 300, 2, 0.8) * (dist == 5.0)[:, None]
        a[:, :2] += z
        b[:, :2] += z
        for agent, h, x in ((0, a, np.zeros(300)), (1, b, dist)):
            keys = {"condition": "control", "episode": e, "agent": agent, "t": np.arange(300)}
            hidden.append(pd.DataFrame(h, columns=[f"h_{i}" for i in range(d)]).assign(**keys))
            steps.append(pd.DataFrame({**keys, "x_cm": x, "y_cm": 20.0}))
    return pd.concat(hidden, ignore_index=True), pd.concat(steps, ignore_index=True)


def test_the_plsc_table_counts_calibrated_shared_dimensions_only_where_planted():
    hidden, steps = hidden_and_steps()
    table = plsc_table(hidden, steps, rng=0, draws=49)
    assert table["n_shared"].tolist() == [2, 0, 0] and table["n_episodes"].tolist() == [6, 6, 6]
    assert table["n_steps"].tolist() == [720, 720, 360]
    # the paper's procedure is unchanged by the calibrated count (its draws come from a spawned stream)
    assert table["n_significant"].tolist() == plsc_table(hidden, steps, rng=0, draws=9)["n_significant"].tolist()


def test_the_collapse_table_finds_fewer_shared_dimensions_far():
    hidden, steps = hidden_and_steps(episodes=8)  # 8: the exact test's smallest p is 2 / 2^8 (6 gives 2 / 64)
    table = plsc_collapse_table(hidden, steps, draws=49, rng=0)
    assert list(table.columns) == COLLAPSE_COLUMNS and len(table) == 1
    row = table.iloc[0]
    assert row["near_hi_cm"] == 10.0 and row["far_lo_cm"] == 100.0 and row["n_steps"] == 480
    assert row["effect"] < 0 and row["p"] < ALPHA and row["n_episodes"] == 8 and row["reason"] == ""
    lonely = plsc_collapse_table(hidden[hidden["agent"] == 0], steps)
    assert lonely.loc[0, "reason"] == "agents 0 and 1 share no step" and list(lonely.columns) == COLLAPSE_COLUMNS
