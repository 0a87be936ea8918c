"""What a decisive recipe verdict costs: the chance that a part's decision over seeds settles, for a design.

The recipe decides a part from the seeds' effects ``y_1..y_k`` by the t interval
over seeds at level 1 - 2 alpha / family against the part's smallest effect of
interest delta (:func:`efish.claims.decision.over_seeds`). A seed's effect is its
own estimate over its episodes, so it varies for two reasons: seeds differ
(between-seed SD ``tau``: training is chaotic) and a seed's estimate over n
episodes is noisy (``sigma / sqrt(n)``, ``sigma`` the spread of one episode's
contribution). With ``omega = sqrt(tau^2 + sigma^2 / n)``:

- the interval (mean +- c s / sqrt(k), c the one-sided critical t, s the seeds'
  SD) lies beyond +delta (**holds**) when the mean exceeds delta + c s / sqrt(k),
  within +-delta (**absent**; **holds** for a "no difference" part) when it lies
  in [-delta + c s / sqrt(k), delta - c s / sqrt(k)], and so on: given s each is
  a normal probability, because the mean of normal effects is independent of
  their SD, and :func:`decision_probabilities` averages it over the distribution
  of s (exact up to quadrature; for the one-sided outcomes this is the
  noncentral t, computed so that it stays finite where scipy's ``nct`` gives NaN).

More episodes shrink only ``sigma^2 / n``; only more seeds shrink ``tau``. So
the planner separates the two from the run itself (:func:`components`): the
variance of the seeds' effects estimates ``omega^2`` at the run's episodes, the
seeds' own standard errors (from their intervals) estimate ``sigma^2 / n``, and
``tau^2`` is the difference (at least 0): the DerSimonian-Laird
method-of-moments split of random-effects meta-analysis.

A decision against delta cannot settle when the true effect sits at delta
(there both "holds" and "absent" stay below alpha, whatever the design), so the
planner asks two questions that can be answered: how likely the verdict is
**holds** if the true effect is twice delta in the paper's direction, and how
likely it is **absent** if there is no effect (:data:`SCENARIOS`), and for each
the fewest seeds that reach :data:`TARGET` (80%, the convention of power
analysis: Cohen 1988). Pure scipy: nothing here reads a table.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import NamedTuple

import numpy as np
from scipy import stats

#: The chance of a decisive verdict a design should reach (the conventional power of 80%).
TARGET = 0.8
#: The planner's two questions: (name, true effect in units of delta in the paper's direction, verdict sought).
#: A "no difference" part reads "holds" where the others read "absent" (its claim is the absence).
SCENARIOS = (("effect 2 delta", 2.0, "holds"), ("no effect", 0.0, "absent"))
#: Values of the seeds' SD the decision probabilities average over (:func:`_seeds_sds`): errors below 1e-3.
QUADRATURE = 4000
#: The most seeds a design search tries before it answers "beyond reach".
MAX_SEEDS = 1000


class Components(NamedTuple):
    """The variance components of a part's effect over seeds (:func:`components`): the seeds' mean effect, the
    between-seed SD ``tau``, the SD ``sigma`` of one unit's (episode's) contribution, the number of seeds and the
    mean number of units per seed."""

    effect: float
    tau: float
    sigma: float
    seeds: int
    units: float

    def seed_sd(self, units: float | None = None) -> float:
        """The SD of one seed's effect at ``units`` units per seed (default: the run's): sqrt(tau^2 + sigma^2 / n)."""
        n = self.units if units is None else units
        return float(np.sqrt(self.tau ** 2 + self.sigma ** 2 / n))


def components(effects: Sequence[float], standard_errors: Sequence[float], units: Sequence[float]) -> Components:
    """Split the spread of the seeds' ``effects`` into between-seed and within-seed parts: ``standard_errors``
    are each seed's own SE of its effect at its ``units`` (episodes); sigma^2 is the mean of SE^2 x n, tau^2 the
    variance of the effects minus the mean SE^2 (at least 0)."""
    y, se, n = (np.asarray(v, np.float64) for v in (effects, standard_errors, units))
    if y.size < 2 or not (y.size == se.size == n.size):
        raise ValueError(f"components need at least 2 seeds with an effect, SE and n each; got {y.size}, {se.size}, "
                         f"{n.size}")
    if not (np.isfinite(y).all() and np.isfinite(se).all() and (se >= 0).all() and (n > 0).all()):
        raise ValueError("components need finite effects, finite SEs >= 0 and n > 0")
    total = float(y.var(ddof=1))
    within = float(np.mean(se ** 2))
    return Components(float(y.mean()), float(np.sqrt(max(0.0, total - within))),
                      float(np.sqrt(np.mean(se ** 2 * n))), int(y.size), float(n.mean()))


def standard_error(low: float, high: float, level: float) -> float:
    """The SE a two-sided interval [low, high] at ``level`` implies under normality: its width over 2 z."""
    return (high - low) / (2 * stats.norm.ppf(0.5 + level / 2))


def _critical(seeds: int, alpha: float, family: int) -> float:
    """The one-sided critical t of the recipe's interval (level 1 - 2 alpha / family, so alpha / family a side)."""
    return float(stats.t.ppf(1 - alpha / family, seeds - 1))


def _seeds_sds(sd: float, seeds: int) -> np.ndarray:
    """:data:`QUADRATURE` equally likely values of the SD of ``seeds`` normal effects of SD ``sd`` (the midpoints of
    as many equal slices of its distribution: s^2 (k - 1) / sd^2 is chi-square with k - 1 df), so that a mean
    over them is an expectation over s."""
    u = (np.arange(QUADRATURE) + 0.5) / QUADRATURE
    return sd * np.sqrt(stats.chi2.ppf(u, seeds - 1) / (seeds - 1))


def _mean_in(theta: float, sd: float, seeds: int, lo: np.ndarray, hi: np.ndarray) -> float:
    """P(lo(s) < the seeds' mean < hi(s)), averaged over the seeds' SD s (``lo``, ``hi`` at each of its
    :func:`_seeds_sds` values): the mean of normal effects is N(theta, sd^2 / k) and independent of their SD."""
    se = sd / np.sqrt(seeds)
    inside = stats.norm.cdf((hi - theta) / se) - stats.norm.cdf((lo - theta) / se)
    return float(np.clip(np.where(hi > lo, inside, 0.0).mean(), 0.0, 1.0))


def decision_probabilities(theta: float, sd: float, seeds: int, sign: int | None, delta: float, alpha: float,
                           family: int = 1) -> dict[str, float]:
    """The chance of each decision of :func:`efish.claims.decision.over_seeds` when ``seeds`` seeds' effects are
    N(``theta``, ``sd``^2) (theta in the part's units, signed as the data are). Keys: holds, absent, opposite,
    inconclusive, not decidable; they sum to 1."""
    if seeds < 2:
        raise ValueError(f"a decision over seeds needs at least 2 seeds, not {seeds}")
    if not (delta > 0 and sd > 0):
        raise ValueError(f"delta and the seeds' SD must be positive, got {delta} and {sd}")
    c = _critical(seeds, alpha, family)
    root = np.sqrt(seeds)
    t = -theta if sign is not None and sign < 0 else theta  # the paper's direction positive
    half = c * _seeds_sds(sd, seeds) / root  # the interval's half-width at each value of the seeds' SD
    inf = np.full_like(half, np.inf)

    def chance(lo: np.ndarray, hi: np.ndarray) -> float:
        return _mean_in(t, sd, seeds, lo, hi)

    beyond = chance(delta + half, inf)       # low > +delta
    against = chance(-inf, -delta - half)    # high < -delta
    within = chance(-delta + half, delta - half)
    out = dict.fromkeys(("holds", "absent", "opposite", "inconclusive", "not decidable"), 0.0)
    if sign == 0:
        out.update(holds=within, opposite=beyond + against)
        wide = half >= delta  # at least 2 delta wide: the width alone rules the absence out
        out["not decidable"] = chance(np.where(wide, -delta - half, 0.0), np.where(wide, delta + half, 0.0))
    elif sign is None:
        below = chance(-inf, delta - half)  # high < +delta
        out.update(holds=beyond, absent=below)
    else:
        out.update(holds=beyond, absent=within, opposite=against)
    out["inconclusive"] = max(0.0, 1.0 - sum(out.values()))
    return out


def scenario_verdict(sign: int | None, sought: str) -> str:
    """The verdict a scenario seeks for a part of this ``sign``: a "no difference" part's claim is the absence, so
    where the others seek "absent" it seeks "holds", and the effect of 2 delta it would call "opposite"."""
    if sign == 0:
        return {"absent": "holds", "holds": "opposite"}[sought]
    return sought


def seeds_needed(components_: Components, sign: int | None, delta: float, alpha: float, theta: float, sought: str,
                 family: int = 1, units: float | None = None, target: float = TARGET) -> int | None:
    """The fewest seeds (at ``units`` episodes each, default the run's) whose decision reaches ``sought`` with
    probability ``target`` when the true effect is ``theta``; None when :data:`MAX_SEEDS` do not."""
    sd = components_.seed_sd(units)

    def chance(k: int) -> float:
        return decision_probabilities(theta, sd, k, sign, delta, alpha, family)[sought]

    if chance(MAX_SEEDS) < target:
        return None
    lo, hi = 2, MAX_SEEDS
    if chance(lo) >= target:
        return lo
    while hi - lo > 1:  # the chance grows with the seeds: bisect for the first k that reaches the target
        mid = (lo + hi) // 2
        lo, hi = (lo, mid) if chance(mid) >= target else (mid, hi)
    return hi

