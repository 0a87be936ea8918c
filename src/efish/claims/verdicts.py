"""Verdicts: what a claim's tested parts carry, and the rules that turn them into the claim's verdict.

A claim of the paper (docs/claims/index.md) often says several things at once
(C10: two ablations cut food, a third keeps it and raises EOD probability...).
Each thing is one :class:`Part`: an effect with the paper's sign, an interval,
an n, a p and a verdict; :func:`combine` makes the claim's one row of them and
:func:`part_rows` a row per part (``claim_parts.parquet``, which keeps each
part's effect and interval, e.g. to follow them along training).

Verdicts (docs/claims/index.md#verdicts, rule 10) are decisions against the
part's smallest effect of interest delta (:mod:`efish.claims.deltas`), made by
:func:`efish.claims.decision.decide` on the part's interval at level
1 - 2 alpha / family (its Bonferroni share of the comparisons it is tested
with): **holds** = the interval lies beyond delta in the paper's direction;
**absent** = within +-delta (no effect as large as delta); **opposite** =
beyond delta the other way; **inconclusive** = none of these; a "no
difference" part (sign 0) swaps the roles (within +-delta holds). **not
decidable** = the data cannot carry the decision (a condition at a ceiling or
floor, a test that cannot reach p < 2 alpha at its n, an interval at least
2 delta wide for a "no difference" part), with the reason; **not run** = no
table or no testable data, with the reason. The part's ``p`` stays its test
against no effect (information; not what the verdict rests on).

A claim's verdict (:func:`claim_verdict`) is
:func:`efish.claims.decision.claim_decision` over its deciding parts:
**opposite** when a part is opposite and its p of "beyond delta the other way"
(:func:`opposite_p`), Holm-adjusted over the claim's deciding parts, is below
alpha; else **holds** when every deciding part holds; **absent** when every
decidable part is absent; **not decidable** when no part is decidable (a part
that did not run counts as not decidable: what was not tested cannot carry the
claim); **not run** when no part ran; **inconclusive** otherwise (e.g. some
parts hold and others are absent: the ``parts`` tally says which).

A part may be reported *beside* a claim without deciding it (``decides=False``,
e.g. the Methods' 4-agent mute design beside the Results' 2-agent one): its
verdict is shown in the reason, the claim's verdict ignores it.

Pure rules: nothing here reads a table or draws a random number.
"""

from __future__ import annotations

from collections.abc import Iterable
from dataclasses import dataclass

import numpy as np
from scipy import stats

from .decision import DECISIONS, claim_decision, decide

VERDICTS = (*DECISIONS, "not run")
ROW_COLUMNS = ["claim", "panel", "statistic", "effect", "ci_low", "ci_high", "n", "p", "verdict", "parts", "reason"]
#: One row per (claim, part) (:func:`part_rows`): the part's label, its statistic, the paper's sign (+1, -1; 0 for
#: "no difference"; NaN for "any difference" or a part that did not run), its effect, its interval at level
#: 1 - 2 alpha / family and how it was made (``ci_method``), n, the p of its test against no effect (Holm-adjusted
#: over ``family`` comparisons; 1: none), ``p_floor`` the smallest p its test can give at its n after that
#: correction, ``reference`` the median of the term its effect subtracts (what a relative delta scales), ``delta``
#: its smallest effect of interest in its units (for "no difference" the equivalence margin), ``p_opposite`` the
#: one-sided p of "beyond delta against the paper" (:func:`opposite_p`), its verdict, whether it decides the
#: claim, and its reason. The recipe (:mod:`efish.claims.recipe`) reads ``effect``, ``delta`` and ``verdict``.
PART_COLUMNS = ["claim", "part", "statistic", "sign", "effect", "ci_low", "ci_high", "ci_method", "n", "p", "family",
                "p_floor", "reference", "delta", "p_opposite", "verdict", "decides", "reason"]
#: The fewest units (episodes, agent-episodes) a part needs to be tested at all; with fewer it is ``not run``.
MIN_UNITS = 2
NAN_CI = (np.nan, np.nan)


@dataclass(frozen=True)
class Outcome:
    """What a part computes: effect (paper's units), p, n, the paper's sign, interval, and a note or why-NaN reason.

    ``sign``: +1 or -1, the direction the paper reports; 0, the paper reports no
    difference; None, any difference (an excess over a null expectation).
    ``ci`` is the interval at level 1 - 2 alpha / ``family`` (the one a decision
    against delta reads, :mod:`efish.claims.decision`); ``ci_method`` says how
    it was made. ``verdict`` overrides the rule for a part decided by a
    criterion, not a test ("not decidable" at a ceiling or floor). ``p_floor``
    is the smallest p the part's test can give at its n, after its
    multiplicity correction. ``family``: the number of comparisons ``p`` is
    Holm-adjusted over (1: none). ``reference``: the median of the term the
    effect subtracts (the control's), which a delta relative to it scales.
    """

    effect: float
    p: float
    n: int
    sign: int | None
    ci: tuple[float, float] = NAN_CI
    reason: str = ""
    verdict: str | None = None
    ci_method: str = ""
    p_floor: float = 0.0
    family: int = 1
    reference: float = np.nan


@dataclass(frozen=True)
class Part:
    """One tested statement of a claim, with its verdict and the paper's sign (:class:`Outcome`; None when the
    part did not run)."""

    label: str
    statistic: str
    effect: float = np.nan
    ci: tuple[float, float] = NAN_CI
    n: int = 0
    p: float = np.nan
    verdict: str = "not run"
    reason: str = ""
    decides: bool = True
    sign: int | None = None
    ci_method: str = ""
    family: int = 1
    p_floor: float = np.nan
    reference: float = np.nan
    delta: float = np.nan
    p_opposite: float = np.nan


def interval_level(alpha: float, family: int = 1) -> float:
    """The level of a part's interval: 1 - 2 alpha / ``family``, whose ends are the one-sided tests at alpha /
    ``family`` that a decision against delta makes (the Bonferroni share of a family of comparisons).

    >>> round(interval_level(0.05), 3), round(interval_level(0.05, 4), 3)
    (0.9, 0.975)
    """
    return 1 - 2 * alpha / family


def opposite_p(effect: float, ci: tuple[float, float], sign: int | None, delta: float, level: float,
               family: int = 1) -> float:
    """The one-sided p that the effect lies beyond ``delta`` against the paper's ``sign`` (either way for a "no
    difference" part), from the part's interval ``ci`` at ``level`` (Altman and Bland's p from an interval, BMJ
    2011: the half-width on that side over the normal quantile is the standard error), times ``family``, capped
    at 1. It is below alpha / family x family = alpha exactly when the interval lies beyond delta that way, so
    Holm over a claim's parts (:func:`claim_verdict`) confirms an "opposite" only its interval shows. 1 for an
    "any difference" part (an excess cannot be opposite) or an unbounded interval.

    >>> round(opposite_p(-0.5, (-0.8, -0.3), +1, 0.1, 0.9), 4), round(opposite_p(0.5, (0.3, 0.8), +1, 0.1, 0.9), 4)
    (0.0005, 0.9995)
    """
    low, high = ci
    if sign is None or not np.isfinite([effect, low, high, delta]).all():
        return 1.0
    if sign < 0:
        effect, low, high = -effect, -high, -low  # the paper's direction positive
    z = float(stats.norm.ppf(0.5 + level / 2))

    def beyond(gap: float, half: float) -> float:
        """p that the effect lies beyond a bound ``gap`` away (positive: the estimate is on the bound's far side)."""
        if half <= 0:
            return 0.0 if gap < 0 else 1.0
        return float(stats.norm.cdf(gap / (half / z)))
    against = beyond(effect + delta, high - effect)  # "effect < -delta", from the upper half-width
    if sign == 0:
        against = min(against, beyond(delta - effect, effect - low))  # or "effect > +delta", from the lower
    return float(min(1.0, against * family))


def decide_outcome(out: Outcome, delta: float, alpha: float) -> tuple[str, str, float]:
    """A tested part's verdict, its reason and :func:`opposite_p`, against its smallest effect of interest
    ``delta`` (in the effect's units; module docstring). Not decidable where the test cannot reach p < 2 alpha at
    its n (``p_floor``: its interval could not exclude any effect). A part with a p but no interval (a permutation
    test of a count, C20's collapse) is decided by its point estimate and p: holds (or opposite) when p < alpha and
    the estimate lies beyond delta in (against) the paper's direction, inconclusive otherwise (never absent: no
    interval bounds the effect).

    >>> decide_outcome(Outcome(0.5, 0.01, 10, +1, (0.3, 0.7)), 0.1, 0.05)[0]
    'holds'
    >>> decide_outcome(Outcome(-2.0, 0.001, 10, -1), 0.5, 0.05)[0], decide_outcome(Outcome(-0.2, 0.001, 10, -1), 0.5, 0.05)[0]
    ('holds', 'inconclusive')
    """
    level = interval_level(alpha, out.family)
    low, high = out.ci
    if out.p_floor >= 2 * alpha:
        return "not decidable", (f"cannot reach p < {2 * alpha:g} at n = {out.n} (the smallest p its test can give "
                                 f"is {out.p_floor:.3g}), so its {level:.3g} interval cannot exclude an effect"), 1.0
    if np.isnan(low) and np.isnan(high):
        oriented = out.effect * (1 if out.sign is None or out.sign >= 0 else -1)
        significant = out.p < alpha
        if significant and oriented > delta and out.sign != 0:
            return "holds", f"p = {out.p:.3g} and the effect beyond delta {delta:.3g} (no interval)", 1.0
        if significant and out.sign is not None and (oriented < -delta or (out.sign == 0 and oriented > delta)):
            return "opposite", f"p = {out.p:.3g} and the effect beyond delta {delta:.3g} the other way", out.p
        return "inconclusive", f"no interval, and p = {out.p:.3g} with the effect {out.effect:.3g} against delta " \
                               f"{delta:.3g}", 1.0
    verdict = decide(low, high, out.sign, delta)
    where = f"{level:.3g} interval [{_fmt(low)}, {_fmt(high)}] against delta {delta:.3g}"
    if verdict == "not decidable":
        where += f": at least 2 delta wide, it cannot lie within +-{delta:.3g} at this n"
    return verdict, where, opposite_p(out.effect, out.ci, out.sign, delta, level, out.family)


def tally(verdicts: Iterable[str]) -> str:
    """The ``parts`` column: how many deciding parts have each verdict, in :data:`VERDICTS` order.

    >>> tally(["holds", "absent", "holds"])
    '2 holds, 1 absent'
    """
    v = list(verdicts)
    return ", ".join(f"{v.count(x)} {x}" for x in VERDICTS if x in v)


def claim_verdict(parts: Iterable[Part], alpha: float) -> str:
    """A claim's verdict from its deciding parts (module docstring): :func:`efish.claims.decision.claim_decision`
    over their verdicts and :func:`opposite_p`'s (Holm), a part that did not run counting as not decidable; not
    run when none ran.

    >>> claim_verdict([Part("a", "", verdict="holds"), Part("b", "", verdict="not run")], 0.05)
    'inconclusive'
    """
    parts = list(parts)
    if all(p.verdict == "not run" for p in parts):
        return "not run"
    decisions = ["not decidable" if p.verdict == "not run" else p.verdict for p in parts]
    p_opposite = [p.p_opposite if np.isfinite(p.p_opposite) else 1.0 for p in parts]
    return claim_decision(decisions, p_opposite, alpha)


def _fmt(x: float) -> str:
    return f"{x:.3g}" if np.isfinite(x) else "NaN"


def combine(claim: str, panel: str, parts: list[Part], alpha: float) -> dict:
    """The claim's row: its verdict over its deciding parts (:func:`claim_verdict`) and their tally; effect,
    interval, n and p of the first deciding part that was decided.

    With several parts the reason lists each: ``label: verdict (effect, delta)``
    and its own reason, so the row says which statement carried the verdict;
    a part reported beside the claim (``decides`` False) is marked so and does
    not enter the verdict.
    """
    deciding = [p for p in parts if p.decides] or parts
    shown = next((p for p in deciding if p.verdict not in ("not run", "not decidable")), deciding[0])
    if len(parts) == 1:
        reason = shown.reason
    else:
        reason = "; ".join(f"{p.label}{'' if p.decides else ' (beside, not deciding)'}: {p.verdict}"
                           + (f" (effect {_fmt(p.effect)}, delta {_fmt(p.delta)})" if np.isfinite(p.effect) else "")
                           + (f" [{p.reason}]" if p.reason else "") for p in parts)
    statistic = shown.statistic if len(parts) == 1 else f"{shown.label}: {shown.statistic}"
    return {"claim": claim, "panel": panel, "statistic": statistic, "effect": shown.effect,
            "ci_low": shown.ci[0], "ci_high": shown.ci[1], "n": shown.n, "p": shown.p,
            "verdict": claim_verdict(deciding, alpha), "parts": tally(p.verdict for p in deciding), "reason": reason}


def part_rows(claim: str, parts: Iterable[Part]) -> list[dict]:
    """The claim's rows of :data:`PART_COLUMNS`, one per part in the claim's order (the row :func:`combine` makes
    summarises them in its reason; these keep each part's effect, interval and p, e.g. to follow them along
    training, :mod:`efish.claims.stages`)."""
    return [{"claim": claim, "part": p.label, "statistic": p.statistic,
             "sign": np.nan if p.sign is None else float(p.sign), "effect": p.effect, "ci_low": p.ci[0],
             "ci_high": p.ci[1], "ci_method": p.ci_method, "n": p.n, "p": p.p, "family": p.family,
             "p_floor": p.p_floor, "reference": p.reference, "delta": p.delta, "p_opposite": p.p_opposite,
             "verdict": p.verdict, "decides": p.decides, "reason": p.reason}
            for p in parts]
