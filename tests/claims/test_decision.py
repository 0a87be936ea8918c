"""Decisions against a smallest effect of interest: planted effects beyond delta, of zero, between 0 and delta and of
the opposite sign, over seeds; the rule's calibration at delta; Holm over a claim's parts."""

from __future__ import annotations

import numpy as np
import pytest

from efish.claims.decision import claim_decision, decide, holm, over_seeds

DELTA, ALPHA = 1.0, 0.05


@pytest.mark.parametrize("low, high, sign, expected", [
    (1.2, 3.0, +1, "holds"), (-0.5, 0.9, +1, "absent"), (-3.0, -1.1, +1, "opposite"), (0.5, 2.0, +1, "inconclusive"),
    (-3.0, -1.2, -1, "holds"), (1.1, 2.0, -1, "opposite"), (-0.9, 0.9, -1, "absent"),
    (-0.9, 0.9, 0, "holds"), (1.5, 2.0, 0, "opposite"), (-2.0, -1.5, 0, "opposite"), (0.5, 1.5, 0, "inconclusive"),
    (-1.5, 1.5, 0, "not decidable"), (1.5, 2.0, None, "holds"), (-0.2, 0.8, None, "absent"),
    (0.5, 1.5, None, "inconclusive"), (-3.0, -2.0, None, "absent"), (np.nan, 1.0, +1, "not decidable"),
])
def test_the_interval_against_delta(low, high, sign, expected):
    assert decide(low, high, sign, DELTA) == expected


def test_a_delta_must_be_positive():
    with pytest.raises(ValueError, match="positive"):
        decide(0.0, 1.0, +1, 0.0)


def share(mean: float, seeds: int, sign: int | None = +1, runs: int = 400, sd: float = 1.0, seed: int = 0) -> dict:
    """How often each decision comes out over ``runs`` recipes of ``seeds`` seeds whose effects are N(mean, sd)."""
    rng = np.random.default_rng(seed)
    out: dict[str, int] = {}
    for _ in range(runs):
        d = over_seeds(rng.normal(mean, sd, seeds), sign, DELTA, ALPHA).decision
        out[d] = out.get(d, 0) + 1
    return {k: v / runs for k, v in out.items()}


def test_an_effect_beyond_delta_holds():
    assert share(3.0, seeds=6).get("holds", 0) > 0.9


def test_no_effect_with_enough_seeds_is_absent():
    assert share(0.0, seeds=40).get("absent", 0) > 0.9


def test_an_effect_below_delta_is_inconclusive_at_few_seeds_and_absent_at_many():
    assert share(0.5, seeds=4).get("inconclusive", 0) > 0.8
    assert share(0.5, seeds=200, runs=200).get("absent", 0) > 0.9


def test_the_opposite_sign_beyond_delta_is_opposite():
    assert share(-3.0, seeds=6).get("opposite", 0) > 0.9
    assert share(3.0, seeds=6, sign=-1).get("opposite", 0) > 0.9


def test_a_no_difference_part_holds_within_delta_and_is_opposite_beyond_it():
    assert share(0.0, seeds=40, sign=0).get("holds", 0) > 0.9
    assert share(3.0, seeds=6, sign=0).get("opposite", 0) > 0.9


@pytest.mark.parametrize("mean, decision", [(DELTA, "holds"), (-DELTA, "opposite")])
def test_at_delta_a_part_is_decided_beyond_it_at_most_alpha_of_the_time(mean, decision):
    """An effect exactly at the edge: the one-sided test the interval makes is at its level (2,000 recipes)."""
    rate = share(mean, seeds=6, runs=2000, seed=1).get(decision, 0)
    assert rate <= ALPHA + 3 * np.sqrt(ALPHA * (1 - ALPHA) / 2000)
    assert rate > ALPHA / 3  # and not far below it: the interval is not needlessly wide


def test_holm_matches_its_definition():
    np.testing.assert_allclose(holm([0.01, 0.04, 0.03, 0.5]), [0.04, 0.09, 0.09, 0.5])


def test_a_claim_of_eight_parts_at_the_edge_is_wrongly_opposite_at_most_alpha_of_the_time():
    """Every part's effect exactly at -delta: without Holm a claim of 8 parts would be opposite about 1 - 0.95^8
    (a third) of the time; with it, at most alpha (1,000 simulated claims)."""
    rng = np.random.default_rng(2)
    wrong = 0
    for _ in range(1000):
        parts = [over_seeds(rng.normal(-DELTA, 1.0, 6), +1, DELTA, ALPHA) for _ in range(8)]
        wrong += claim_decision([p.decision for p in parts], [p.p_opposite for p in parts], ALPHA) == "opposite"
    assert wrong / 1000 <= ALPHA + 3 * np.sqrt(ALPHA * (1 - ALPHA) / 1000)


def test_a_claim_holds_only_when_every_part_does():
    assert claim_decision(["holds", "holds"], [1, 1], ALPHA) == "holds"
    assert claim_decision(["holds", "inconclusive"], [1, 1], ALPHA) == "inconclusive"
    assert claim_decision(["absent", "not decidable"], [1, 1], ALPHA) == "absent"
    assert claim_decision(["not decidable"], [1], ALPHA) == "not decidable"
