"""Stat rows agree with scipy on known cases; stars at the thresholds; degenerate input gives NaN with a reason."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest
from scipy import stats as sps

from efish.analysis.stats import (
    STAT_COLUMNS,
    dunnett_vs_control,
    mann_whitney,
    signed_rank_test,
    spearman,
    stars,
    wilcoxon_paired,
)


def groups_table(rng, means=(0.0, 0.5, 1.5), n=12) -> pd.DataFrame:
    names = ["control", "a", "b"]
    return pd.DataFrame({"condition": np.repeat(names, n), "episode": np.tile(np.arange(n), 3),
                         "food": np.concatenate([rng.normal(m, 1.0, n) for m in means])})


@pytest.mark.parametrize(("p", "expected"), [(0.2, "ns"), (0.0500001, "ns"), (0.05, "*"), (0.0100001, "*"),
                                             (0.01, "**"), (1e-3, "***"), (1.0001e-4, "***"), (1e-4, "****"),
                                             (0.0, "****"), (np.nan, "n/a")])
def test_stars_at_the_thresholds(p, expected):
    assert stars(p) == expected


def test_dunnett_matches_scipy():
    df = groups_table(np.random.default_rng(0))
    out = dunnett_vs_control(df, "food", "condition", "control")
    samples = {g: df.loc[df["condition"] == g, "food"].to_numpy() for g in ("a", "b", "control")}
    ref = sps.dunnett(samples["a"], samples["b"], control=samples["control"], rng=np.random.default_rng(0))
    assert list(out.columns) == STAT_COLUMNS and list(out["group"]) == ["a", "b"]
    np.testing.assert_allclose(out["statistic"], ref.statistic)
    np.testing.assert_allclose(out["p"], ref.pvalue)
    np.testing.assert_allclose(out["effect"], [samples[g].mean() - samples["control"].mean() for g in "ab"])
    assert (out["n"] == 12).all() and (out["test"] == "dunnett").all() and (out["reason"] == "").all()
    assert out.loc[1, "stars"] == stars(out.loc[1, "p"])


def test_dunnett_with_one_constant_group_is_finite_and_quiet():
    df = groups_table(np.random.default_rng(1))
    df.loc[df["condition"] == "a", "food"] = 3.0  # scipy's per-sample precision check would warn here
    out = dunnett_vs_control(df, "food", "condition", "control")
    assert np.isfinite(out["p"]).all() and (out["reason"] == "").all()


def test_mann_whitney_matches_scipy():
    df = groups_table(np.random.default_rng(2))
    out = mann_whitney(df, "food", "condition", "control").set_index("group")
    x, y = (df.loc[df["condition"] == g, "food"].to_numpy() for g in ("b", "control"))
    ref = sps.mannwhitneyu(x, y, alternative="two-sided")
    assert out.loc["b", "statistic"] == pytest.approx(ref.statistic)
    assert out.loc["b", "p"] == pytest.approx(ref.pvalue)
    assert out.loc["b", "effect"] == pytest.approx(np.median(x) - np.median(y))
    assert out.loc["b", "test"] == "mann-whitney" and out.loc["b", "effect_kind"] == "median difference"


def test_wilcoxon_pairs_by_key_whatever_the_row_order():
    df = groups_table(np.random.default_rng(3))
    shuffled = df.sample(frac=1.0, random_state=0)
    out = wilcoxon_paired(shuffled, "food", "condition", "control", pair_on="episode").set_index("group")
    x, y = (df.loc[df["condition"] == g, "food"].to_numpy() for g in ("a", "control"))
    ref = sps.wilcoxon(x, y)
    assert out.loc["a", "statistic"] == pytest.approx(ref.statistic)
    assert out.loc["a", "p"] == pytest.approx(ref.pvalue)
    assert out.loc["a", "effect"] == pytest.approx(np.median(x - y)) and out.loc["a", "n"] == 12


def integer_differences(rng, n: int) -> np.ndarray:
    """Paired differences as food counts give them: small integers, so ties and zeros are common."""
    return rng.integers(-4, 5, n).astype(np.float64)


@pytest.mark.parametrize("alternative", ["two-sided", "less", "greater"])
def test_signed_rank_test_equals_scipys_wilcoxon(alternative):
    """The counted permutation branch (n <= 13 with ties or zeros) and every delegated case give scipy's
    statistic and p, to the last bits: integer differences (ties, zeros, one sign only), half-integer ones
    (average ranks of a tie across a zero), continuous ones (scipy's exact branch) and n past 13."""
    rng = np.random.default_rng(11)
    cases = [integer_differences(rng, n) for n in [*range(1, 12), 13, 15] for _ in range(4 if n < 12 else 1)]
    cases += [np.abs(integer_differences(rng, 9)) + 1, np.array([0.5, -0.5, 0.0, 1.5, 1.5, -2.0]),
              rng.normal(0.3, 1.0, 10), rng.normal(0.0, 1.0, 30)]
    counted = 0
    for d in cases:
        if not np.any(d):
            continue
        ref = sps.wilcoxon(d, alternative=alternative)
        statistic, p = signed_rank_test(d, alternative)
        assert statistic == pytest.approx(float(ref.statistic), rel=1e-12, abs=0), d
        assert p == pytest.approx(float(ref.pvalue), rel=1e-12, abs=1e-15), d
        counted += d.size <= 13 and (np.any(d == 0) or np.unique(np.abs(d[d != 0])).size < np.count_nonzero(d))
    assert counted > 25  # most cases took the counted branch


def test_spearman_matches_scipy():
    rng = np.random.default_rng(4)
    df = pd.DataFrame({"x": rng.normal(size=30)})
    df["y"] = df["x"] + rng.normal(size=30)
    out = spearman(df, "x", "y")
    ref = sps.spearmanr(df["x"], df["y"])
    assert out.loc[0, "effect"] == pytest.approx(ref.statistic) and out.loc[0, "p"] == pytest.approx(ref.pvalue)


def test_degenerate_inputs_give_nan_with_a_reason():
    df = pd.DataFrame({"condition": ["control"] * 4 + ["a"] * 4, "episode": list(range(4)) * 2, "food": 2.0})
    for out in (dunnett_vs_control(df, "food", "condition", "control"),
                mann_whitney(df, "food", "condition", "control"),
                wilcoxon_paired(df, "food", "condition", "control", "episode")):
        assert out["p"].isna().all() and (out["reason"] != "").all() and (out["stars"] == "n/a").all()
    one = df.iloc[[0, 1, 2, 3, 4]]
    assert "fewer than 2" in dunnett_vs_control(one, "food", "condition", "control").loc[0, "reason"]
    nan = df.assign(food=np.nan)
    assert dunnett_vs_control(nan, "food", "condition", "control")["p"].isna().all()
    assert mann_whitney(nan, "food", "condition", "control").loc[0, "reason"].startswith("fewer than 1")
    assert wilcoxon_paired(nan, "food", "condition", "control", "episode").loc[0, "reason"] == "no complete pairs"
    assert spearman(df.assign(x=np.arange(8.0)), "x", "food").loc[0, "reason"] == "food is constant"
    assert dunnett_vs_control(df[df["condition"] == "control"], "food", "condition", "control").loc[0, "reason"] \
        == "no group besides the control"


def test_programming_errors_raise_one_line():
    df = pd.DataFrame({"condition": ["control", "a"], "episode": [0, 0], "food": [1.0, 2.0]})
    with pytest.raises(ValueError, match="lacks columns"):
        mann_whitney(df, "eaten", "condition", "control")
    with pytest.raises(ValueError, match="control 'none'"):
        dunnett_vs_control(df, "food", "condition", "none")
    with pytest.raises(ValueError, match="ambiguous"):
        wilcoxon_paired(pd.concat([df, df]), "food", "condition", "control", "episode")
