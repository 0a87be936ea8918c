"""The smallest effect of interest (delta) of every part of every claim, fixed before any run is judged.

A part's verdict is to be decided against its delta (docs/claims/index.md#smallest-effects): the part holds
when its interval lies beyond delta in the paper's direction, is absent within +-delta, opposite beyond delta
the other way, and inconclusive otherwise; for a "no difference" part (sign 0) delta is the equivalence margin.
A delta comes from the paper's numbers, the authors' methods or a one-sentence domain argument, never from a
run's effects, so it is a table here, keyed by (claim id, part label) exactly as the claims (:mod:`.fig2` ..
:mod:`.fig6`) label their parts, with the reason beside each value.

A delta is in the part's own units, or a fraction of the part's :data:`REFERENCE_MEDIAN` where the measure has
no natural unit of size (food, bites, power): a rule such as "a fifth of the control's median" is fixed in
advance even though the control's median is read from the run. Nothing here reads a table.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

__all__ = ["REFERENCE_MEDIAN", "SMALLEST_EFFECTS", "SOURCES", "SmallestEffect", "smallest_effect"]

#: Where a delta comes from: the paper's numbers, the authors' methods (their code and analyses), or a
#: one-sentence domain argument.
SOURCES = ("paper", "authors' methods", "domain")
#: The reference of a relative delta: the median, over the part's episodes, of the term its effect subtracts (the
#: control of a paired part, uniform4 in C13, the alone condition in C14, the next-highest class in C16, near and
#: the larger agent in C21).
REFERENCE_MEDIAN = "reference median"


@dataclass(frozen=True)
class SmallestEffect:
    """A part's smallest effect of interest.

    ``delta`` is in ``units`` when ``relative_to`` is None; otherwise it is a fraction of that reference (only
    :data:`REFERENCE_MEDIAN`), and ``at_least`` (in ``units``) keeps it from falling below the measure's
    resolution (one whole pellet) where the reference is small. ``source`` is one of :data:`SOURCES`; ``why``
    is the one-sentence argument for the value.
    """

    delta: float
    relative_to: str | None
    units: str
    source: str
    why: str
    at_least: float = 0.0

    def __post_init__(self):
        if not (math.isfinite(self.delta) and self.delta > 0):
            raise ValueError(f"a smallest effect must be positive and finite, not {self.delta}")
        if self.relative_to not in (None, REFERENCE_MEDIAN):
            raise ValueError(f"a delta is absolute or relative to {REFERENCE_MEDIAN!r}, not {self.relative_to!r}")
        if not (math.isfinite(self.at_least) and self.at_least >= 0) or (self.at_least and not self.relative_to):
            raise ValueError(f"at_least {self.at_least} must be finite, >= 0, and only beside a relative delta")
        if self.source not in SOURCES or not self.why.strip():
            raise ValueError(f"source {self.source!r} must be one of {SOURCES}, with a reason (why)")

    def absolute(self, reference: float | None = None) -> float:
        """The delta in the part's units: ``delta`` itself, or ``delta`` x |``reference``| and at least
        ``at_least`` for a relative one (``reference``: the part's :data:`REFERENCE_MEDIAN`)."""
        if self.relative_to is None:
            return self.delta
        if reference is None or not math.isfinite(reference):
            raise ValueError(f"a delta relative to the {self.relative_to} needs a finite reference, not {reference}")
        return max(self.delta * abs(reference), self.at_least)

    @property
    def shown(self) -> str:
        """The delta as the docs' table shows it: ``0.05``, or ``20% of the reference median, at least 1``."""
        if self.relative_to is None:
            return f"{self.delta:.3g}"
        floor = f", at least {self.at_least:.3g}" if self.at_least else ""
        return f"{self.delta:.0%} of the {self.relative_to}{floor}"


def _rho(what: str = "") -> SmallestEffect:
    return SmallestEffect(0.1, None, "Spearman rho", "domain",
                          f"Cohen's small correlation (0.1){what}.")


# ------------------------------------------------------------------ values shared by several parts
FOOD = SmallestEffect(0.2, REFERENCE_MEDIAN, "pellets per episode", "domain",
                      "A fifth of the reference condition's median food (the ±20% band of conventional equivalence "
                      "limits and of rule 3's margin), so that cut and kept food are told apart by one line, and at "
                      "least one whole pellet.", at_least=1.0)
FOOD_AGENT = SmallestEffect(0.2, REFERENCE_MEDIAN, "pellets per agent-episode", "domain",
                            "A fifth of the alone condition's median food of the agent at the same size (the ±20% "
                            "band of conventional equivalence limits), and at least one whole pellet.", at_least=1.0)
EOD_PROBABILITY = SmallestEffect(0.05, None, "EOD probability per step", "authors' methods",
                                 "One discharge more per 20 steps, the window of the authors' rolling EOD rate "
                                 "(4.15 Hz at 83 steps per second).")
SPACING = SmallestEffect(2.0, None, "cm", "domain",
                         "One body diameter (agents are discs of radius 1 cm, touching at 2 cm), the smallest change "
                         "of spacing one fish's place can make.")
SIZE_GAP = SmallestEffect(0.05, None, "size (0 to 1)", "domain",
                          "A twentieth of the size range: 15% of the mean gap (1/3) of two uniform sizes when the "
                          "larger always bites or chases, and 5% of a size-0 agent's top speed (speed scales with 1 + size).")
SKILL = SmallestEffect(0.02, None, "decoding skill (held-out R²)", "domain",
                       "Cohen's small increment of explained variance (f² = 0.02): 2% of the target's variance.")
EOD_RATE = SmallestEffect(4.15, None, "Hz", "authors' methods",
                          "One discharge more per 20-step window of the authors' rolling EOD rate (83 Hz / 20).")
W_EXCESS = SmallestEffect(0.1, None, "Kendall's W - 1/n", "domain",
                          "The conventional small Kendall's W (0.1, after Cohen), counted above its null expectation "
                          "1/n; the excess reaches 1 - 1/n.")
POWER = SmallestEffect(0.2, REFERENCE_MEDIAN, "wideband power", "domain",
                       "A fifth of the reference median power (near, or the larger agent), as for food: about a "
                       "tenth of the activity's amplitude.")

#: (claim id, part label) -> its smallest effect of interest, for every part a claim of
#: :data:`efish.claims.registry.CLAIMS` produces (the tests check both ways), in the paper's order.
SMALLEST_EFFECTS: dict[tuple[str, str], SmallestEffect] = {
    ("C1", "tortuosity"): SmallestEffect(
        0.05, None, "tortuosity (path / displacement)", "domain",
        "A path 5% longer than its displacement, an arc leaving the straight line at about 30 degrees (straight "
        "paths have tortuosity 1)."),
    ("C2", "aligned beyond straight homing"): SmallestEffect(
        0.05, None, "fraction of steps", "domain",
        "A twentieth of the steps, a tenth of the way from chance (a random heading is aligned half the time) to "
        "full alignment."),
    ("C3", "alignment"): _rho(" of alignment with time within an episode"),
    ("C4", "power law"): SmallestEffect(
        1.0, None, "nats per episode", "domain",
        "Kass and Raftery's threshold of positive evidence (2 ln B = 2): the power law 1 nat likelier than the "
        "exponential per episode, both laws having one parameter."),
    **{("C5", to): W_EXCESS for to in ("agent", "food", "wall")},
    **{("C6", event): EOD_RATE for event in ("ate", "bit", "was_bitten")},
    ("C7", "biter larger, patchy4"): SIZE_GAP,
    ("C7", "biter larger, square2"): SIZE_GAP,
    ("C7", "win ratio slope, patchy4"): SmallestEffect(
        0.1, None, "win ratio per unit size", "domain",
        "Ten percentage points of win ratio (0 to 1) across the whole size range (0 to 1)."),
    ("C8", "food ~ size"): SmallestEffect(
        1.0, None, "pellets per unit size", "domain",
        "One whole pellet per episode between the smallest (0) and the largest (1) possible agent: food is eaten "
        "in whole pellets."),
    ("C8", "Theil ~ size Theil"): _rho(" between episodes' food and size inequality"),
    ("C9", "rho"): _rho(" of EOD probability with size within an episode"),
    **{("C10", label): FOOD for label in ("group food, M off", "group food, A off", "solo food, M off",
                                          "solo food, A off", "group food, K off (equivalent)")},
    ("C10", "EOD probability, K off"): EOD_PROBABILITY,
    ("C10", "bites, K off"): SmallestEffect(
        0.2, REFERENCE_MEDIAN, "bites per episode", "domain",
        "A fifth of the control's median bites, as for food, and at least one whole bite.", at_least=1.0),
    ("C10", "nearest-neighbour distance, K off"): SPACING,
    ("C11", "food, self-only"): FOOD,
    ("C11", "food, cons-only (equivalent)"): FOOD,
    ("C11", "EOD probability, self-only"): EOD_PROBABILITY,
    ("C11", "EOD probability, cons-only"): EOD_PROBABILITY,
    ("C11", "food, self-only (authors' mode)"): FOOD,
    ("C11", "EOD probability, self-only (authors' mode)"): EOD_PROBABILITY,
    ("C12", "group food, 2 agents"): FOOD,
    ("C12", "spacing, 2 agents"): SPACING,
    ("C12", "group food, 4 agents (Methods)"): FOOD,
    ("C12", "spacing, 4 agents (Methods)"): SPACING,
    ("C13", "food, patchy vs uniform"): FOOD,
    ("C13", "excess Theil, patchy vs uniform (equivalent)"): SmallestEffect(
        0.02, None, "Theil T (nats)", "domain",
        "The Theil T of four agents sharing 30/30/20/20% (0.020), a tenth of the food moved from one half of the "
        "group to the other, and the chance T of 75 pellets shared at random (rule 6)."),
    ("C13", "iso per-fish food vs n"): _rho(" of the food per fish with the patch count"),
    ("C13", "free per-fish food vs n"): _rho(" of the food per fish with the patch count"),
    ("C13", "iso excess Theil vs n"): _rho(" of the excess inequality with the patch count"),
    ("C13", "free excess Theil vs n"): _rho(" of the excess inequality with the patch count"),
    # one part per social condition of config/assay/onepatch.yaml, B's size rising
    **{("C14", f"B social, {c}"): FOOD_AGENT for c in ("A_gt_B", "A_eq_B", "A_lt_B")},
    ("C14", "A social vs alone (equivalent)"): FOOD_AGENT,
    ("C14", "B food vs B size"): _rho(" of the intruder's food with its size"),
    **{("C15", label): SmallestEffect(
        0.1, None, "reach rate (fraction of episodes)", "authors' methods",
        "One episode in ten, the episodes the authors ran per bot condition (Fig 5I,J).")
       for label in ("frozen vs moving bot", "emitting vs silent bot")},
    ("C16", "chaser larger"): SIZE_GAP,
    ("C16", "bites early"): SmallestEffect(
        0.05, None, "fraction of the bout", "authors' methods",
        "One bin of the authors' 20-bin histogram of the normalised bite time within an interaction (Fig 5O)."),
    ("C16", "confronting bites most"): SmallestEffect(
        0.2, REFERENCE_MEDIAN, "bites per pair-step", "domain",
        "A fifth above the next-highest class's median rate, as for food, and at least one bite per 1,600 "
        "pair-steps (an episode's length).", at_least=1 / 1600),
    ("C17", "low-dimensional"): SmallestEffect(
        0.1, None, "fraction of the width", "domain",
        "A tenth of the network's width (51 of 512 units) below the half the criterion names, so that a "
        "low-dimensional state uses at most 40% of its units."),
    ("C17", "D_eff grows with N, K on"): _rho(" of D_eff with group size"),
    ("C17", "growth larger with K than without"): SmallestEffect(
        1 / 3, None, "effective dimensions per agent", "domain",
        "One effective dimension more with Knollenorgans than without across the assay's group sizes 1 to 4 "
        "(three agents added)."),
    ("C18", "err vs bearing"): SKILL,
    ("C19", "agent features best"): SKILL,
    ("C19", "food near > far"): SKILL,
    ("C20", "r1 falls with distance"): _rho(" of the shared correlation with the distance bin"),
    ("C20", "collapse beyond the last edge"): SmallestEffect(
        0.5, None, "shared dimensions", "domain",
        "Half a dimension: counts are whole, so the loss of one shared dimension lies beyond it and a median "
        "between two windows' counts does not."),
    ("C21", "far > near"): POWER,
    ("C21", "smaller carries more"): POWER,
}


def smallest_effect(claim: str, part: str) -> SmallestEffect:
    """The smallest effect of interest of ``claim``'s part labelled ``part``; a one-line KeyError naming a part
    without one (a part added to a claim needs its delta here before it can be decided)."""
    try:
        return SMALLEST_EFFECTS[claim, part]
    except KeyError:
        raise KeyError(f"no smallest effect of interest for {claim} part {part!r}: add one to "
                       "efish.claims.deltas.SMALLEST_EFFECTS") from None
