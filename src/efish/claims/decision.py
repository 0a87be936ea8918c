"""Decisions against a smallest effect of interest (rule 10, docs/claims/index.md#smallest-effects).

A test at a fixed alpha asks "is the effect non-zero?"; as data grow, small
non-zero effects move into the coin-flip zone before they are decided, so two
runs of one recipe disagree however large they are (the third claims audit).
A decision against a part's smallest effect of interest delta
(:mod:`efish.claims.deltas`) settles instead. With the part's interval oriented
so that the paper's direction is positive:

- **holds**: the interval lies beyond +delta (the effect is at least as large as
  the smallest that matters, in the paper's direction);
- **absent**: the interval lies within +-delta (no effect as large as delta);
- **opposite**: the interval lies beyond -delta;
- **inconclusive**: otherwise.

A "no difference" part (sign 0) swaps the roles: within +-delta it holds, beyond
delta either way it is opposite, and where the interval is at least 2 delta wide
(so that it could not lie within +-delta whatever the effect) it is not
decidable. An "any difference" part (sign None, an excess over a null
expectation that every departure raises) holds beyond +delta and is absent
below it, never opposite.

Each decision is a pair of one-sided tests at the interval's level: an
interval of level 1 - 2 alpha lies beyond delta exactly when the one-sided test
of "effect > delta" rejects at alpha, and within +-delta exactly when both
one-sided tests of the equivalence (TOST) do. So the interval to pass is the
1 - 2 alpha one (:func:`t_interval`'s ``level``), and an effect below delta that
data keep narrowing settles as absent instead of flipping between verdicts.

For the recipe, :func:`over_seeds` makes the interval from the seeds' effects
(a t interval over seeds, which covers its nominal level at 4-10 seeds, where a
percentile bootstrap covered 80-90% for 95%) and the one-sided p of "beyond
delta the other way"; :func:`claim_decision` combines a claim's parts with
Holm's step-down over those p's, so that the chance of any wrong "opposite"
among a claim's parts stays at alpha. Pure rules: nothing here reads a table.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import NamedTuple

import numpy as np
from scipy import stats

DECISIONS = ("holds", "absent", "opposite", "inconclusive", "not decidable")


def decide(low: float, high: float, sign: int | None, delta: float) -> str:
    """The decision of a part with interval [``low``, ``high``] (the effect's units), the paper's ``sign`` (+1, -1,
    0 "no difference", None "any difference") and smallest effect of interest ``delta`` > 0 (module docstring).

    >>> [decide(lo, hi, +1, 0.1) for lo, hi in ((0.2, 0.5), (-0.05, 0.08), (-0.5, -0.2), (0.05, 0.3))]
    ['holds', 'absent', 'opposite', 'inconclusive']
    >>> decide(0.2, 0.5, -1, 0.1), decide(-0.05, 0.05, 0, 0.1), decide(-0.3, 0.3, 0, 0.1)
    ('opposite', 'holds', 'not decidable')
    """
    if not (np.isfinite(delta) and delta > 0):
        raise ValueError(f"delta must be positive and finite, not {delta}")
    if not (np.isfinite(low) and np.isfinite(high)) or low > high:
        return "not decidable"
    if sign is not None and sign < 0:
        low, high = -high, -low  # the paper's direction positive
    beyond, against, within = low > delta, high < -delta, low >= -delta and high <= delta
    if sign == 0:
        if within:
            return "holds"
        if beyond or against:
            return "opposite"
        return "not decidable" if high - low >= 2 * delta else "inconclusive"
    if beyond:
        return "holds"
    if within or (sign is None and high < delta):
        return "absent"
    if against and sign is not None:
        return "opposite"
    return "inconclusive"


class SeedsDecision(NamedTuple):
    """A part decided over the seeds' effects (:func:`over_seeds`): their mean, the 1 - 2 alpha / family t interval,
    the decision, and the one-sided p that the effect lies beyond delta against the paper's direction (for a "no
    difference" part: beyond delta either way), which :func:`claim_decision` adjusts over a claim's parts."""

    effect: float
    low: float
    high: float
    decision: str
    p_opposite: float


def t_interval(effects: Sequence[float], level: float) -> tuple[float, float, float]:
    """Mean of ``effects`` and its two-sided t interval at ``level`` (k - 1 df); the interval is the mean itself when
    every effect is the same."""
    y = np.asarray(effects, np.float64)
    if y.size < 2 or not np.isfinite(y).all():
        raise ValueError(f"a t interval over seeds needs 2 finite effects, got {y.tolist()}")
    mean, se = float(y.mean()), float(y.std(ddof=1)) / np.sqrt(y.size)
    half = float(stats.t.ppf(0.5 + level / 2, y.size - 1)) * se
    return mean, mean - half, mean + half


def over_seeds(effects: Sequence[float], sign: int | None, delta: float, alpha: float, family: int = 1
               ) -> SeedsDecision:
    """The recipe's decision of a part from the seeds' ``effects``: the t interval at 1 - 2 alpha / ``family``
    (``family``: the comparisons the part's test shares its alpha with, Bonferroni) decided by :func:`decide`."""
    mean, low, high = t_interval(effects, 1 - 2 * alpha / family)
    mean, low, high = float(mean), float(low), float(high)
    y = np.asarray(effects, np.float64)
    se, df = float(y.std(ddof=1)) / np.sqrt(y.size), y.size - 1
    if sign is None:
        p_opposite = 1.0  # an excess cannot be opposite
    elif se == 0:
        p_opposite = 0.0 if decide(mean, mean, sign, delta) == "opposite" else 1.0
    else:
        direction = -1.0 if sign is not None and sign < 0 else 1.0
        against = stats.t.cdf((direction * mean + delta) / se, df)  # p of "effect < -delta" (paper's direction +)
        beyond = stats.t.sf((direction * mean - delta) / se, df)    # p of "effect > +delta"
        p_opposite = float(min(against, beyond)) if sign == 0 else float(against)  # the side the interval tests
    return SeedsDecision(mean, low, high, decide(low, high, sign, delta), min(1.0, p_opposite * family))


def holm(p_values: Sequence[float]) -> np.ndarray:
    """Holm's step-down adjusted p-values (monotone, capped at 1), in the input's order."""
    p = np.asarray(p_values, np.float64)
    order = np.argsort(p, kind="stable")
    adjusted = np.maximum.accumulate((p.size - np.arange(p.size)) * p[order])
    out = np.empty_like(p)
    out[order] = np.minimum(adjusted, 1.0)
    return out


def claim_decision(decisions: Sequence[str], p_opposite: Sequence[float], alpha: float) -> str:
    """A claim's decision from its deciding parts': **opposite** when a part is opposite and its p of "beyond delta
    the other way", Holm-adjusted over the claim's parts, stays below ``alpha`` (so the chance that any part of a
    claim is wrongly opposite is at most alpha); else **holds** when every part holds; **absent** when every
    decidable part is absent; **not decidable** when none is decidable; **inconclusive** otherwise.

    >>> claim_decision(["holds", "holds"], [1.0, 1.0], 0.05), claim_decision(["holds", "opposite"], [1.0, 0.001], 0.05)
    ('holds', 'opposite')
    >>> claim_decision(["holds", "opposite"], [1.0, 0.04], 0.05)  # opposite alone, not after Holm over 2 parts
    'inconclusive'
    """
    if len(decisions) != len(p_opposite):
        raise ValueError(f"{len(decisions)} decisions but {len(p_opposite)} p-values")
    adjusted = holm(p_opposite) if len(decisions) else np.array([])
    if any(d == "opposite" and p < alpha for d, p in zip(decisions, adjusted, strict=True)):
        return "opposite"
    decided = [d for d in decisions if d != "not decidable"]
    if not decided:
        return "not decidable"
    if all(d == "holds" for d in decisions):
        return "holds"
    if all(d == "absent" for d in decided):
        return "absent"
    return "inconclusive"
