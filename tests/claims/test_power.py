"""The planner's decision probabilities against simulated experiments run through the claims' own decisions: the
recipe's over seeds, and a selected seed's part over its episodes (signed-rank, Mann-Whitney, Welch)."""

from __future__ import annotations

import numpy as np
import pytest
from scipy import stats

from efish.claims.decision import over_seeds
from efish.claims.intervals import (
    rank_sum_interval,
    signed_rank_interval,
    smallest_p_rank_sum,
    smallest_p_signed_rank,
    walsh_averages,
)
from efish.claims.parts import signed_rank_outcome
from efish.claims.power import (
    RANK_SUM,
    SIGNED_RANK,
    T_TEST,
    WELCH,
    Components,
    components,
    decision_probabilities,
    own_decision_probabilities,
    own_standard_error,
    own_tail,
    scenario_verdict,
    seeds_needed,
    standard_error,
)
from efish.claims.statistics import welch_difference
from efish.claims.verdicts import Outcome, decide_outcome, interval_level

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


# ------------------------------------------------------------------ the selected seed's own test, simulated
class Levels:
    """What the claims' part builders read of a :class:`efish.claims.context.Context` here: the parts' level."""

    def level(self, family: int = 1) -> float:
        return interval_level(ALPHA, family)


def order_statistic(real, candidates: np.ndarray) -> int:
    """How many of one tie-free sample's ``candidates`` (Walsh averages, pairwise differences) lie below the low end
    of its ``real`` interval: the rank interval's order statistic, the same for every tie-free sample of that size."""
    return int(np.sum(candidates < real.low))


def rank_intervals(candidates: np.ndarray, c: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Each row's Hodges-Lehmann estimate and interval from its sorted ``candidates``: the median, the (c + 1)-th and
    the (M - c)-th of M (unbounded when c < 0: a test that cannot reject)."""
    w = np.sort(candidates, axis=1)
    if c < 0:
        return np.median(w, axis=1), np.full(len(w), -np.inf), np.full(len(w), np.inf)
    return np.median(w, axis=1), w[:, c], w[:, w.shape[1] - 1 - c]


def signed_rank_intervals(d: np.ndarray, family: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The signed-rank intervals of every row of ``d`` at the parts' level over ``family``, vectorised: the order
    statistic of :func:`efish.claims.intervals.signed_rank_interval` itself (:func:`order_statistic`) applied to each
    row's Walsh averages."""
    n = d.shape[1]
    i, j = np.triu_indices(n)
    sample = np.random.default_rng(0).normal(size=n)
    real = signed_rank_interval(sample, 1 - Levels().level(family))
    c = order_statistic(real, walsh_averages(sample)) if np.isfinite(real.low) else -1
    return rank_intervals((d[:, i] + d[:, j]) / 2, c)


def rank_sum_intervals(x: np.ndarray, y: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The Mann-Whitney intervals of every row pair of ``x`` against ``y`` (:func:`efish.claims.intervals.
    rank_sum_interval`'s order statistic applied to the pairwise differences)."""
    sx, sy = np.random.default_rng(0).normal(size=(2, x.shape[1]))
    real = rank_sum_interval(sx, sy, 1 - Levels().level())
    c = order_statistic(real, np.subtract.outer(sx, sy).ravel()) if np.isfinite(real.low) else -1
    return rank_intervals((x[:, :, None] - y[:, None, :]).reshape(len(x), -1), c)


def test_the_vectorised_rank_intervals_are_the_claims_own():
    rng = np.random.default_rng(5)
    for n, family in ((5, 1), (8, 1), (8, 3), (12, 2)):
        d = rng.normal(0.3, 1.0, (15, n))
        est, low, high = signed_rank_intervals(d, family)
        real = [signed_rank_interval(row, 1 - Levels().level(family)) for row in d]
        assert np.array_equal(np.c_[est, low, high], [[r.estimate, r.low, r.high] for r in real]), (n, family)
    for n in (4, 8, 10):
        x, y = rng.normal(0.3, 1.0, (2, 10, n))
        est, low, high = rank_sum_intervals(x, y)
        real = [rank_sum_interval(a, b, 1 - Levels().level()) for a, b in zip(x, y, strict=True)]
        assert np.allclose(np.c_[est, low, high], [[r.estimate, r.low, r.high] for r in real]), n


def verdicts(outcomes: list[Outcome]) -> list[str]:
    """Each outcome's verdict by :func:`efish.claims.verdicts.decide_outcome`, the selected seed's decision."""
    return [decide_outcome(o, DELTA, ALPHA)[0] for o in outcomes]


def shares(found: list[str]) -> dict[str, float]:
    return {v: found.count(v) / len(found) for v in set(found)}


def assert_within_3_points(predicted: dict[str, float], observed: dict[str, float], design) -> None:
    assert abs(sum(predicted.values()) - 1) < 1e-9
    for decision, p in predicted.items():
        assert abs(observed.get(decision, 0.0) - p) < 0.03, (design, decision, p, observed)


OWN_EXPERIMENTS = 4000
#: Paired parts over n episodes (the claims' commonest test): (sign, true effect, SD of a difference, n, family).
SIGNED_RANK_DESIGNS = [
    (+1, 2 * DELTA, 0.2, 8, 1),      # an effect of 2 delta at the laptop's 8 episodes
    (+1, 0.0, 0.1, 8, 1),            # no effect
    (-1, -2 * DELTA, 0.15, 6, 1),    # the paper's direction negative, 6 episodes
    (+1, -2 * DELTA, 0.2, 8, 2),     # the opposite of the paper's direction, in a family of 2
    (+1, 0.0, 0.08, 12, 3),          # C10's family of 3
    (0, 0.02, 0.1, 10, 1),           # a "no difference" part
    (+1, 2 * DELTA, 0.3, 24, 1),     # the study's episodes
    (+1, 2 * DELTA, 0.1, 5, 2),      # too few differences to reject in a family of 2: not decidable
]


@pytest.mark.parametrize("design", SIGNED_RANK_DESIGNS, ids=[f"sign {d[0]}, effect {d[1]:g}, n {d[3]}, family {d[4]}"
                                                             for d in SIGNED_RANK_DESIGNS])
def test_the_selected_seeds_signed_rank_part_matches_planted_experiments_within_3_points(design):
    """Planted paired differences, each experiment's signed-rank interval decided as a seed's part is: the planner's
    normal approximation (a t interval at the rank test's exact level, sigma the Hodges-Lehmann estimate's spread
    per unit, sqrt(pi / 3) times the differences' SD for normal data) within 3 points of what the test does."""
    sign, theta, sd, n, family = design
    d = np.random.default_rng(n * 31 + family).normal(theta, sd, (OWN_EXPERIMENTS, n))
    est, low, high = signed_rank_intervals(d, family)
    floor = min(1.0, family * smallest_p_signed_rank(n))
    found = verdicts([Outcome(e, np.nan, n, sign, (lo, hi), family=family, p_floor=floor)
                      for e, lo, hi in zip(est, low, high, strict=True)])
    predicted = own_decision_probabilities(theta, sd * np.sqrt(np.pi / 3), n, SIGNED_RANK, sign, DELTA, ALPHA,
                                           family)
    assert_within_3_points(predicted, shares(found), design)
    for row, verdict in zip(d[:5], found, strict=False):  # the claims' own part builder decides the same
        assert decide_outcome(signed_rank_outcome(Levels(), row, sign, family=family), DELTA, ALPHA)[0] == verdict


#: Mann-Whitney parts, two groups of n units each: (sign, true shift, SD within a group, n).
RANK_SUM_DESIGNS = [
    (+1, 2 * DELTA, 0.15, 8),   # scipy's exact p (8 a group)
    (+1, 0.0, 0.06, 8),
    (-1, -2 * DELTA, 0.2, 12),  # its normal approximation
    (0, 0.0, 0.08, 10),         # a "no difference" part (C14's A unaffected)
]


@pytest.mark.parametrize("design", RANK_SUM_DESIGNS, ids=[f"sign {d[0]}, effect {d[1]:g}, n {d[3]}"
                                                          for d in RANK_SUM_DESIGNS])
def test_the_selected_seeds_mann_whitney_part_matches_planted_experiments_within_3_points(design):
    """Two planted groups, each experiment's Mann-Whitney interval decided as a seed's part is (its floor that of
    :func:`efish.claims.parts.mann_whitney_part`): the plan (a pooled t interval at the test's exact level, sigma
    sqrt(2 pi / 3) times the groups' SD for normal data) within 3 points."""
    sign, theta, sd, n = design
    rng = np.random.default_rng(n * 17 + (sign or 0) + 5)
    x, y = rng.normal(theta, sd, (OWN_EXPERIMENTS, n)), rng.normal(0.0, sd, (OWN_EXPERIMENTS, n))
    est, low, high = rank_sum_intervals(x, y)
    floor = smallest_p_rank_sum(n, n)
    found = verdicts([Outcome(e, np.nan, n, sign, (lo, hi), p_floor=floor)
                      for e, lo, hi in zip(est, low, high, strict=True)])
    predicted = own_decision_probabilities(theta, sd * np.sqrt(2 * np.pi / 3), n, RANK_SUM, sign, DELTA, ALPHA)
    assert_within_3_points(predicted, shares(found), design)


#: Mean differences by Welch's t (C13's excess Theil T), n units in all over two groups: (sign, true difference,
#: SD within a group, n).
WELCH_DESIGNS = [
    (+1, 2 * DELTA, 0.15, 16),
    (+1, 0.0, 0.08, 16),
    (0, 0.0, 0.1, 24),          # the part's own question: no difference
    (0, 2 * DELTA, 0.1, 12),    # a difference where the paper reports none
]


@pytest.mark.parametrize("design", WELCH_DESIGNS, ids=[f"sign {d[0]}, effect {d[1]:g}, n {d[3]}"
                                                       for d in WELCH_DESIGNS])
def test_the_selected_seeds_welch_part_matches_planted_experiments_within_3_points(design):
    """Two planted groups of n / 2, each experiment's Welch interval (scipy's, vectorised: the one
    :func:`efish.claims.statistics.welch_difference` gives C13's part) decided by
    :func:`~efish.claims.verdicts.decide_outcome`: the plan (a t interval, n - 2 df, sigma twice the groups' SD: a
    difference of two means of n / 2) within 3 points."""
    sign, theta, sd, n = design
    rng = np.random.default_rng(n * 13 + (sign or 0))
    x, c = rng.normal(theta, sd, (OWN_EXPERIMENTS, n // 2)), rng.normal(0.0, sd, (OWN_EXPERIMENTS, n // 2))
    level = Levels().level()
    ci = stats.ttest_ind(x, c, axis=1, equal_var=False).confidence_interval(level)
    diff = x.mean(axis=1) - c.mean(axis=1)
    for i in range(10):  # the claims' own statistic gives the same
        assert welch_difference(x[i], c[i], level)[2] == pytest.approx((ci.low[i], ci.high[i]))
    found = verdicts([Outcome(d, np.nan, n, sign, (lo, hi)) for d, lo, hi in zip(diff, ci.low, ci.high, strict=True)])
    predicted = own_decision_probabilities(theta, 2 * sd, n, WELCH, sign, DELTA, ALPHA)
    assert_within_3_points(predicted, shares(found), design)


def test_read_back_from_the_rank_interval_recovers_the_estimates_spread():
    """SE^2 x n read back from the claims' signed-rank intervals by their own critical value estimates the
    Hodges-Lehmann estimate's variance x n (the sigma the plan assumes); the normal quantile overstates it by a
    quarter at 8 differences."""
    rng = np.random.default_rng(3)
    for n in (6, 8, 12):
        est, low, high = signed_rank_intervals(rng.normal(0.0, 1.0, (OWN_EXPERIMENTS, n)), 1)
        spread = est.std() * np.sqrt(n)
        own = np.sqrt(np.mean(own_standard_error(low, high, SIGNED_RANK, n, ALPHA) ** 2) * n)
        normal = np.sqrt(np.mean(standard_error(low, high, 1 - 2 * ALPHA) ** 2) * n)
        assert abs(own / spread - 1) < 0.08 and normal / spread > 1.08, (n, own, normal, spread)
