"""The planner's decision probabilities against simulated experiments run through the recipe's own decision."""

from __future__ import annotations

import numpy as np
import pytest

from efish.claims.decision import over_seeds
from efish.claims.power import (
    RANK_SUM,
    SIGNED_RANK,
    T_TEST,
    Components,
    components,
    decision_probabilities,
    own_decision_probabilities,
    own_tail,
    scenario_verdict,
    seeds_needed,
    standard_error,
)

ALPHA, DELTA = 0.05, 0.1
EXPERIMENTS = 2000

# (sign, true effect, between-seed SD tau, within-seed SD sigma, episodes per seed, seeds)
DESIGNS = [
    (+1, 2 * DELTA, 0.08, 0.2, 8, 4),      # an effect of 2 delta at the laptop's four seeds
    (+1, 0.0, 0.05, 0.2, 6, 8),            # no effect, eight seeds
    (+1, 0.6 * DELTA, 0.04, 0.1, 6, 12),   # an effect below delta
    (-1, -2.5 * DELTA, 0.1, 0.3, 4, 5),    # the paper's direction negative
    (+1, -2 * DELTA, 0.05, 0.2, 8, 6),     # the opposite of the paper's direction
    (0, 0.02, 0.03, 0.15, 8, 6),           # a "no difference" part
    (0, 0.0, 0.1, 0.4, 4, 4),              # ... too noisy to decide at four seeds
    (None, 1.5 * DELTA, 0.06, 0.2, 8, 4),  # an "any difference" excess
]


def simulated(sign, theta, tau, sigma, episodes, seeds, rng) -> dict[str, float]:
    """Decisions of ``EXPERIMENTS`` planted runs: each seed's true effect drawn with SD tau, its estimate the mean
    of ``episodes`` episodes with SD sigma, decided over the seeds by the recipe's rule."""
    counts: dict[str, int] = {}
    for _ in range(EXPERIMENTS):
        true = rng.normal(theta, tau, seeds)
        effects = rng.normal(true[:, None], sigma, (seeds, episodes)).mean(axis=1)
        decision = over_seeds(effects, sign, DELTA, ALPHA).decision
        counts[decision] = counts.get(decision, 0) + 1
    return {k: v / EXPERIMENTS for k, v in counts.items()}


@pytest.mark.parametrize("design", DESIGNS, ids=[f"sign {d[0]}, effect {d[1]:g}, {d[5]} seeds" for d in DESIGNS])
def test_predicted_decisions_match_planted_experiments_within_3_points(design):
    sign, theta, tau, sigma, episodes, seeds = design
    sd = Components(theta, tau, sigma, seeds, episodes).seed_sd()
    predicted = decision_probabilities(theta, sd, seeds, sign, DELTA, ALPHA)
    assert abs(sum(predicted.values()) - 1) < 1e-9
    observed = simulated(sign, theta, tau, sigma, episodes, seeds, np.random.default_rng(seeds * 7 + episodes))
    for decision, p in predicted.items():
        assert abs(observed.get(decision, 0.0) - p) < 0.03, (decision, p, observed)


def test_an_effect_of_delta_itself_never_settles():
    """At the boundary both one-sided tests sit at their level: no design makes the verdict decisive."""
    for seeds in (4, 40, 400):
        p = decision_probabilities(DELTA, 0.05, seeds, +1, DELTA, ALPHA)
        assert p["holds"] <= ALPHA + 1e-3 and p["absent"] <= ALPHA + 1e-3


def test_components_recover_the_planted_between_and_within_seed_spread():
    rng = np.random.default_rng(1)
    tau, sigma, episodes, seeds = 0.1, 0.3, 8, 12
    estimates = []
    for _ in range(400):
        true = rng.normal(0.2, tau, seeds)
        data = rng.normal(true[:, None], sigma, (seeds, episodes))
        ses = data.std(axis=1, ddof=1) / np.sqrt(episodes)
        c = components(data.mean(axis=1), ses, np.full(seeds, episodes))
        estimates.append((c.tau ** 2, c.sigma ** 2, c.effect))
    tau2, sigma2, effect = np.mean(estimates, axis=0)
    assert abs(sigma2 - sigma ** 2) < 0.05 * sigma ** 2
    assert abs(tau2 - tau ** 2) < 0.2 * tau ** 2  # truncation at 0 biases it up a little
    assert abs(effect - 0.2) < 0.01


def test_no_between_seed_spread_is_estimated_as_none_on_average():
    rng = np.random.default_rng(2)
    taus = []
    for _ in range(400):
        data = rng.normal(0.0, 0.3, (8, 6))
        c = components(data.mean(axis=1), data.std(axis=1, ddof=1) / np.sqrt(6), np.full(8, 6))
        taus.append(c.tau)
    assert np.median(taus) == 0.0


def test_seeds_needed_is_the_first_design_that_reaches_the_target():
    c = Components(effect=0.0, tau=0.08, sigma=0.2, seeds=4, units=8)
    k = seeds_needed(c, +1, DELTA, ALPHA, theta=2 * DELTA, sought="holds")
    chance = [decision_probabilities(2 * DELTA, c.seed_sd(), n, +1, DELTA, ALPHA)["holds"] for n in (k - 1, k)]
    assert chance[0] < 0.8 <= chance[1]
    more_episodes = seeds_needed(c, +1, DELTA, ALPHA, theta=2 * DELTA, sought="holds", units=80)
    assert more_episodes <= k  # episodes shrink only the within-seed part
    assert seeds_needed(c, +1, DELTA, ALPHA, theta=DELTA, sought="holds") is None  # at delta: beyond reach
    assert seeds_needed(c, +1, DELTA, ALPHA, theta=50 * DELTA, sought="holds") == 2


def test_a_no_difference_part_seeks_holds_where_others_seek_absent():
    assert scenario_verdict(0, "absent") == "holds" and scenario_verdict(0, "holds") == "opposite"
    assert scenario_verdict(+1, "absent") == "absent" and scenario_verdict(None, "holds") == "holds"


def test_an_interval_gives_back_its_standard_error():
    assert standard_error(-1.96, 1.96, 0.95) == pytest.approx(1.0, rel=1e-3)


@pytest.mark.parametrize("bad", [dict(seeds=1), dict(sd=0.0), dict(delta=-1.0)])
def test_bad_designs_are_one_line_errors(bad):
    args = dict(theta=0.0, sd=0.1, seeds=4, sign=1, delta=DELTA, alpha=ALPHA) | bad
    with pytest.raises(ValueError):
        decision_probabilities(**args)


def test_the_signed_rank_intervals_level_is_its_exact_one():
    """At 8 differences the signed-rank interval at 90% ends where P(T+ <= 5) = 10 / 256 (not 0.05); at 4 it cannot
    reject at all (2 / 2^4 = 0.125 > 0.1), so the part is not decidable; beyond 50 scipy's p is the normal one."""
    assert own_tail(SIGNED_RANK, 8, ALPHA) == pytest.approx(10 / 256)
    assert own_tail(SIGNED_RANK, 4, ALPHA) == 0.0
    assert own_decision_probabilities(0.5, 0.1, 4, SIGNED_RANK, +1, DELTA, ALPHA)["not decidable"] == 1.0
    assert own_tail(SIGNED_RANK, 60, ALPHA, family=2) == ALPHA / 2
    assert own_tail(RANK_SUM, 3, ALPHA) == 0.0 and own_tail(RANK_SUM, 4, ALPHA) == pytest.approx(2 / 70)


def test_a_t_interval_over_units_is_planned_as_over_seeds():
    """The own plan of a t interval over n units is the recipe's over n seeds: the same noncentral t."""
    for sign, theta in ((+1, 2 * DELTA), (0, 0.0), (None, 0.05)):
        own = own_decision_probabilities(theta, 0.3, 9, T_TEST, sign, DELTA, ALPHA, family=2)
        assert own == pytest.approx(decision_probabilities(theta, 0.3, 9, sign, DELTA, ALPHA, family=2))
