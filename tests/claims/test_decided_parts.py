"""Rule 10 through the real parts: planted tables decided against each part's smallest effect of interest.

Two parts of the registry, run by their claims' own code: C12's "group food, 2 agents" (a paired signed-rank part
whose delta is a fifth of the control's median food, at least one pellet) and C8's "Theil ~ size Theil" (a
Spearman correlation over episodes, delta 0.1, tested by Fisher's z). For each: an effect of the paper's sign
beyond delta holds, no effect over many episodes is absent, the opposite sign beyond delta is opposite, and an
effect between 0 and delta is inconclusive over few episodes and absent over many.
"""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

from efish import claims as cl
from efish.claims.deltas import smallest_effect
from efish.layout import analysis_table

from .test_claims import CFG

CONTROL_FOOD = 50.0  # the control's median food: delta is 10 pellets


def food_part(cut: float, spread: float, episodes: int, seed: int = 0):
    """C12's paired food part on ``episodes`` paired episodes: the muted agent's group eats ``cut`` pellets fewer
    than intact (the paper: fewer, sign -1) plus noise of SD ``spread``; intact eats about 50."""
    rng = np.random.default_rng(seed)
    intact = CONTROL_FOOD + rng.normal(0, 3, episodes)
    muted = intact - cut + rng.normal(0, spread, episodes)
    summary = pd.DataFrame([{"condition": c, "episode": e, "food_total": v, "mean_nn_dist_cm": 20.0}
                            for c, values in (("intact", intact), ("muted", muted)) for e, v in enumerate(values)])
    tables = {analysis_table("behaviour", "mute", "episode_summary"): summary.assign(food_offered=400)}
    return next(p for p in cl.CLAIMS["C12"].assess(tables, CFG)[1] if p.label == "group food, 2 agents")


@pytest.mark.parametrize(("cut", "spread", "episodes", "expected"), [
    (20.0, 2.0, 12, "holds"),  # fewer by twice delta
    (0.0, 2.0, 30, "absent"),  # no cut, many episodes: the interval lies within +-10
    (-20.0, 2.0, 12, "opposite"),  # more food by twice delta
    (5.0, 8.0, 6, "inconclusive"),  # half of delta, few noisy episodes: the interval straddles -10
    (5.0, 8.0, 60, "absent"),  # the same half of delta, many episodes: settles as absent, not "holds"
])
def test_a_paired_part_is_decided_against_a_fifth_of_its_controls_median(cut, spread, episodes, expected):
    part = food_part(cut, spread, episodes)
    assert part.verdict == expected, (part.verdict, part.ci, part.delta, part.reason)
    assert part.reference == pytest.approx(CONTROL_FOOD, abs=2.0)
    assert part.delta == pytest.approx(smallest_effect("C12", "group food, 2 agents").absolute(part.reference))
    assert part.ci[0] <= part.effect <= part.ci[1] and "level 0.9" in part.ci_method
    assert (part.p_opposite < CFG.analysis.claims_alpha) == (expected == "opposite")


def theil_part(r: float, episodes: int, seed: int = 0):
    """C8's correlation part on ``episodes`` episodes whose food and size inequality are bivariate normal with
    correlation ``r`` (the paper: positive)."""
    rng = np.random.default_rng(seed)
    size_t, noise = rng.normal(size=(2, episodes))
    theil = pd.DataFrame({"condition": "control", "episode": np.arange(episodes), "n_agents": 4, "total": 40.0,
                          "size_theil_t": size_t, "theil_t": r * size_t + np.sqrt(1 - r * r) * noise})
    tables = {analysis_table("behaviour", "patchy4", t): frame for t, frame in (
        ("theil", theil), ("food_per_agent", pd.DataFrame(columns=["condition", "episode", "size", "food_eaten"])))}
    return next(p for p in cl.CLAIMS["C8"].assess(tables, CFG)[1] if p.label == "Theil ~ size Theil")


@pytest.mark.parametrize(("r", "episodes", "expected"), [
    (0.8, 60, "holds"),
    (0.0, 3000, "absent"),  # no correlation, many episodes: within +-0.1
    (-0.8, 60, "opposite"),
    (0.05, 15, "inconclusive"),  # half of delta, few episodes
    (0.05, 6000, "absent"),  # half of delta, many episodes
])
def test_a_correlation_part_is_decided_against_a_small_correlation(r, episodes, expected):
    part = theil_part(r, episodes)
    assert part.verdict == expected, (part.verdict, part.ci, part.reason)
    assert part.delta == 0.1 and "Fisher-z" in part.ci_method and part.n == episodes


def test_a_claim_is_opposite_only_when_holm_over_its_parts_confirms_it():
    """C12's two deciding parts: food cut beyond delta (holds) and spacing far below delta the other way
    (opposite, p_opposite tiny): the claim is opposite; with spacing unchanged over many episodes it is
    inconclusive (one part holds, one is absent)."""
    rng = np.random.default_rng(1)
    intact = CONTROL_FOOD + rng.normal(0, 3, 40)

    def run(spacing: float) -> dict:
        rows = [{"condition": c, "episode": e, "food_total": v - (20 if c == "muted" else 0),
                 "mean_nn_dist_cm": 20 + (spacing if c == "muted" else 0) + rng.normal(0, 0.5)}
                for c in ("intact", "muted") for e, v in enumerate(intact)]
        tables = {analysis_table("behaviour", "mute", "episode_summary"): pd.DataFrame(rows).assign(food_offered=400)}
        return cl.CLAIMS["C12"].run(tables, CFG)
    opposite = run(-10.0)  # the paper: spacing rises; here it falls by 5 deltas
    assert opposite["verdict"] == "opposite" and opposite["parts"] == "1 holds, 1 opposite", opposite["reason"]
    mixed = run(0.0)
    assert mixed["verdict"] == "inconclusive" and mixed["parts"] == "1 holds, 1 absent", mixed["reason"]
