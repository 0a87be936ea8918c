"""Verdicts: what a claim's tested parts carry, and the rules that turn them into the claim's verdict.

A claim of the paper (docs/claims/index.md) often says several things at once
(C10: two ablations cut food, a third keeps it and raises EOD probability...).
Each thing is one :class:`Part`: an effect with the paper's sign, a p-value, an
n, an interval and a verdict; :func:`combine` makes the claim's one row of them
and :func:`part_rows` a row per part (``claim_parts.parquet``, which keeps each
part's effect and interval, e.g. to follow them along training).

Verdicts (docs/claims/index.md#verdicts): **holds** = the paper's sign and
p < alpha; **weaker** = the paper's sign but not significant (an effect of the
opposite sign that is not significant is also weaker: nothing refutes the claim,
and the reason says so); **fails** = the opposite sign and significant, or a
criterion that cannot hold; **not decidable** = the data cannot carry the test
(a condition at a ceiling or floor), with the reason; **not run** = no table or
no testable data, with the reason. A part the paper reports as *no difference*
(K-off food in C10) holds when it is *shown equivalent*: its two one-sided tests
(TOST) within the part's margin give p < alpha; it fails when the difference is
significant and larger than the margin; otherwise it is weaker. Every difference
test here is two-sided, so that an effect of the opposite sign can be
significant.

A part may be reported *beside* a claim without deciding it (``decides=False``,
e.g. the Methods' 4-agent mute design beside the Results' 2-agent one): its
verdict is shown in the reason, the claim's verdict ignores it.

Pure rules: nothing here reads a table or draws a random number.
"""

from __future__ import annotations

from collections.abc import Iterable
from dataclasses import dataclass

import numpy as np

VERDICTS = ("holds", "weaker", "fails", "not decidable", "not run")
ROW_COLUMNS = ["claim", "panel", "statistic", "effect", "ci_low", "ci_high", "n", "p", "verdict", "reason"]
#: One row per (claim, part) (:func:`part_rows`): the part's label, its statistic, the paper's sign (+1, -1; 0 for
#: "no difference"; NaN for "any difference" or a part that did not run), its effect, interval, how the interval
#: was made (``ci_method``), n, the p its verdict rests on, the equivalence margin of a "no difference" part and
#: its ratio to the control's typical value, its verdict, whether it decides the claim, and its reason. ``family``
#: is the number of comparisons its p is Holm-adjusted over (1: none) and ``p_floor`` the smallest p its test can
#: give at its n after that correction (what the recipe's verdict, :mod:`efish.claims.recipe`, reads to tell a
#: part too small to decide from one the data cannot carry).
PART_COLUMNS = ["claim", "part", "statistic", "sign", "effect", "ci_low", "ci_high", "ci_method", "n", "p", "family",
                "p_floor", "margin", "margin_ratio", "verdict", "decides", "reason"]
#: The fewest units (episodes, agent-episodes) a part needs to be tested at all; with fewer it is ``not run``.
MIN_UNITS = 2
NAN_CI = (np.nan, np.nan)


@dataclass(frozen=True)
class Outcome:
    """What a part computes: effect (paper's units), p, n, the paper's sign, interval, and a note or why-NaN reason.

    ``sign``: +1 or -1, the direction the paper reports; 0, the paper reports no
    difference (holds when n.s.); None, any difference (holds when significant).
    ``verdict`` overrides the rule for a part decided by a criterion, not a test
    (or "not decidable" at a ceiling). For ``sign`` 0, ``p_equiv`` is the TOST
    p within ``margin`` (in the effect's units) and ``p`` the difference test's;
    ``margin_ratio`` is the margin over the control's typical value.
    ``ci_method`` says how ``ci`` was made (it inverts the test, or resamples).
    ``p_floor`` is the smallest p the part's test can give at its n, after its
    multiplicity correction: at or above alpha the part cannot be significant
    (for sign 0, the TOST p of its data shifted to a zero difference).
    ``family``: the number of comparisons ``p`` is Holm-adjusted over (1: none).
    """

    effect: float
    p: float
    n: int
    sign: int | None
    ci: tuple[float, float] = NAN_CI
    reason: str = ""
    verdict: str | None = None
    p_equiv: float = np.nan
    margin: float = np.nan
    margin_ratio: float = np.nan
    ci_method: str = ""
    p_floor: float = 0.0
    family: int = 1


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
    margin: float = np.nan
    margin_ratio: float = np.nan
    family: int = 1
    p_floor: float = np.nan


def judge(effect: float, p: float, sign: int | None, alpha: float, p_equiv: float = np.nan,
          margin: float = np.nan) -> tuple[str, str]:
    """Verdict and a short reason from an effect, its two-sided p and the paper's sign (module docstring).

    >>> judge(0.3, 0.01, +1, 0.05), judge(-0.3, 0.01, +1, 0.05)[0]
    (('holds', ''), 'fails')
    >>> [judge(e, p, 0, 0.05, pe, 1.0)[0] for e, p, pe in ((0.1, 0.6, 0.01), (2.0, 0.01, 0.9), (0.3, 0.6, 0.3))]
    ['holds', 'fails', 'weaker']
    """
    significant = p < alpha
    if sign is None:
        return ("holds", "") if significant else ("weaker", f"not significant (p = {p:.3g})")
    if sign == 0:
        within = f"within +-{margin:.3g}"
        if p_equiv < alpha:
            return "holds", f"shown equivalent {within} (TOST p = {p_equiv:.3g}; difference p = {p:.3g})"
        if significant and abs(effect) > margin:
            return "fails", f"a significant difference (p = {p:.3g}) beyond the margin {within}; the paper reports none"
        return "weaker", (f"neither shown equivalent {within} (TOST p = {p_equiv:.3g}) nor different beyond it "
                          f"(p = {p:.3g})")
    direction = np.sign(effect) * sign
    if direction > 0:
        return ("holds", "") if significant else ("weaker", f"the paper's sign, not significant (p = {p:.3g})")
    if direction < 0:
        return (("fails", f"opposite sign, significant (p = {p:.3g})") if significant
                else ("weaker", f"opposite sign, not significant (p = {p:.3g})"))
    return "weaker", "zero effect"


def unreachable(verdict: str, p_floor: float, alpha: float, sign: int | None) -> bool:
    """Whether a part that its rule judged ``verdict`` is *not decidable* instead, because its test cannot give
    p < ``alpha`` at its n (``p_floor``, the smallest p it can reach, is >= alpha): the data could not have shown
    what the part tests, so "weaker" would blame the effect for the size of the run. For a "no difference" part
    (``sign`` 0) the floor is its equivalence test's (a margin too narrow for its standard error cannot be shown
    even at a zero difference); such a part may still fail, by its difference test, which has a floor of its own.

    >>> unreachable("weaker", 0.0625, 0.05, +1), unreachable("fails", 0.2, 0.05, 0), unreachable("weaker", 0.01, 0.05, 0)
    (True, False, False)
    """
    return bool(p_floor >= alpha) and not (sign == 0 and verdict == "fails")


def combined_verdict(verdicts: Iterable[str]) -> str:
    """A claim's verdict from its deciding parts': any fails -> fails; every part holds -> holds; a part that
    is weaker, not decidable or not run beside the others makes the claim weaker at best (what was not tested
    cannot carry the claim); nothing decided -> not decidable; none ran -> not run.

    >>> combined_verdict(["holds", "holds"]), combined_verdict(["holds", "not decidable"])
    ('holds', 'weaker')
    >>> combined_verdict(["not decidable", "not run"]), combined_verdict(["weaker", "fails"])
    ('not decidable', 'fails')
    """
    v = list(verdicts)
    decided = [x for x in v if x in ("holds", "weaker", "fails")]
    if not decided:
        return "not decidable" if "not decidable" in v else "not run"
    if "fails" in decided:
        return "fails"
    return "holds" if all(x == "holds" for x in v) else "weaker"


def _fmt(x: float) -> str:
    return f"{x:.3g}" if np.isfinite(x) else "NaN"


def combine(claim: str, panel: str, parts: list[Part]) -> dict:
    """The claim's row: its verdict over all parts; effect, interval, n and p of the first part that ran.

    With several parts the reason lists each: ``label: verdict (effect, p)``
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
                           + (f" (effect {_fmt(p.effect)}, p {_fmt(p.p)})" if np.isfinite(p.effect) else "")
                           + (f" [{p.reason}]" if p.reason else "") for p in parts)
    statistic = shown.statistic if len(parts) == 1 else f"{shown.label}: {shown.statistic}"
    return {"claim": claim, "panel": panel, "statistic": statistic, "effect": shown.effect,
            "ci_low": shown.ci[0], "ci_high": shown.ci[1], "n": shown.n, "p": shown.p,
            "verdict": combined_verdict(p.verdict for p in deciding), "reason": reason}


def part_rows(claim: str, parts: Iterable[Part]) -> list[dict]:
    """The claim's rows of :data:`PART_COLUMNS`, one per part in the claim's order (the row :func:`combine` makes
    summarises them in its reason; these keep each part's effect, interval and p, e.g. to follow them along
    training, :mod:`efish.claims.stages`)."""
    return [{"claim": claim, "part": p.label, "statistic": p.statistic,
             "sign": np.nan if p.sign is None else float(p.sign), "effect": p.effect, "ci_low": p.ci[0],
             "ci_high": p.ci[1], "ci_method": p.ci_method, "n": p.n, "p": p.p, "family": p.family,
             "p_floor": p.p_floor, "margin": p.margin,
             "margin_ratio": p.margin_ratio, "verdict": p.verdict, "decides": p.decides, "reason": p.reason}
            for p in parts]
