"""The smallest effects of interest (efish.claims.deltas, docs/claims/index.md#smallest-effects): one for every part
every claim produces and none for a part no claim produces, each positive, finite, reachable by its statistic and
argued; the docs' table lists exactly the same values."""

from __future__ import annotations

import math
import re

import pytest

from efish import claims as cl
from efish.claims.deltas import REFERENCE_MEDIAN, SMALLEST_EFFECTS, SOURCES, SmallestEffect, smallest_effect
from efish.claims.verdicts import MIN_UNITS

from ..helpers import REPO
from .test_claims import BUILDERS, CFG

#: The largest size an effect in these units can have (math.inf: no bound), so that a delta the statistic cannot
#: reach is caught; every unit a delta uses must be here, so a new one needs its bound decided.
REACHABLE = {
    "Spearman rho": 1.0,
    "Kendall's W - 1/n": 1 - 1 / MIN_UNITS,  # W - 1/n reaches 1 - 1/n, at the fewest episodes a part is tested on
    "fraction of steps": 1.0,
    "EOD probability per step": 1.0,
    "reach rate (fraction of episodes)": 1.0,
    "size (0 to 1)": 1.0,
    "decoding skill (held-out R²)": 1.0,  # 1 - SSE / SSE of the mean: at most 1 for either target
    "fraction of the bout": 0.5,  # the median bite phase (0 to 1) minus 0.5
    "fraction of the width": 0.5,  # D_eff / width (0 to 1) minus the criterion's 0.5
    "win ratio per unit size": 1.0,  # a win ratio (0 to 1) across the size range (0 to 1)
    "Theil T (nats)": math.log(4),  # Theil T of four agents is at most ln 4
    "Hz": 83.0,  # an agent discharges at most once per step
    "cm": 70.0,  # the side of the arenas whose spacing the parts compare
    "bites per pair-step": 1.0,
    "tortuosity (path / displacement)": math.inf,
    "nats per episode": math.inf,
    "pellets per unit size": math.inf,
    "pellets per episode": math.inf,
    "pellets per agent-episode": math.inf,
    "bites per episode": math.inf,
    "effective dimensions per agent": math.inf,
    "shared dimensions": math.inf,
    "wideband power": math.inf,
}


def labels(cid: str, tables: dict) -> list[str] | None:
    """The labels of claim ``cid``'s parts on ``tables``; None when the claim could not even be set up (it then
    returns one part labelled with its id, and its parts' labels are unknown)."""
    parts = cl.CLAIMS[cid].parts(tables, CFG)
    return None if [p.label for p in parts] == [cid] else [p.label for p in parts]


@pytest.fixture(scope="module")
def produced() -> list[tuple[str, str]]:
    """(claim, part label) of every part every registered claim produces. Without tables each part is labelled
    and not run (a missing table fails its computation, not its label); a claim whose labels come from its tables
    (C14's from the conditions onepatch recorded) cannot be set up without them and runs on its planted tables
    (test_claims.py's builders). Every claim on its planted tables gives the same labels, only slower."""
    found = []
    for cid in cl.CLAIMS:
        mine = labels(cid, {}) or labels(cid, BUILDERS[cid](False))
        assert mine, f"{cid} cannot be set up even on its planted tables"
        found += [(cid, label) for label in mine]
    return found


def test_labels_without_tables_are_those_of_the_planted_tables():
    for cid in ("C5", "C12", "C13"):  # labels built in loops, parts reported beside
        assert labels(cid, {}) == labels(cid, BUILDERS[cid](False)), cid
    assert labels("C14", {}) is None


def test_every_part_a_claim_produces_has_a_smallest_effect(produced):
    missing = [key for key in produced if key not in SMALLEST_EFFECTS]
    assert not missing, f"parts without a smallest effect of interest: {missing}"
    assert len(produced) == len(set(produced))


def test_no_smallest_effect_is_left_for_a_part_no_claim_produces(produced):
    stale = [key for key in SMALLEST_EFFECTS if key not in set(produced)]
    assert not stale, f"smallest effects of parts no claim produces: {stale}"


def test_every_delta_is_positive_finite_argued_and_from_an_allowed_source():
    for key, entry in SMALLEST_EFFECTS.items():
        assert math.isfinite(entry.delta) and entry.delta > 0, key
        assert entry.source in SOURCES, key
        assert entry.why.strip() and entry.why.rstrip().endswith("."), key
        assert entry.units.strip(), key
        assert entry.relative_to in (None, REFERENCE_MEDIAN), key


def test_every_delta_can_be_reached_by_its_statistic():
    unknown = sorted({e.units for e in SMALLEST_EFFECTS.values()} - set(REACHABLE))
    assert not unknown, f"units without a decided bound in REACHABLE: {unknown}"
    for key, entry in SMALLEST_EFFECTS.items():
        bound = REACHABLE[entry.units]
        if entry.relative_to is None:
            assert entry.delta < bound, (key, entry.delta, bound)
        else:
            # a fraction of the reference: never wider than half of it (rule 3's cap on a margin), and a floor the
            # statistic can reach
            assert entry.delta <= 0.5 and entry.at_least < bound, key
    rho = [e.delta for e in SMALLEST_EFFECTS.values() if e.units == "Spearman rho"]
    assert rho and max(rho) <= 0.5  # a correlation's delta well below 1


def test_a_part_without_a_delta_is_named_in_one_line():
    with pytest.raises(KeyError, match=r"C7 part 'biter larger, nowhere'") as err:
        smallest_effect("C7", "biter larger, nowhere")
    assert "\n" not in str(err.value)
    assert smallest_effect("C1", "tortuosity") is SMALLEST_EFFECTS["C1", "tortuosity"]


def test_a_relative_delta_scales_with_its_reference_and_keeps_its_floor():
    food = smallest_effect("C10", "group food, K off (equivalent)")
    assert food.relative_to == REFERENCE_MEDIAN
    assert food.absolute(50.0) == pytest.approx(10.0)
    assert food.absolute(-50.0) == pytest.approx(10.0)
    assert food.absolute(2.0) == food.at_least == 1.0  # a fifth of 2 pellets is below one whole pellet
    with pytest.raises(ValueError, match="needs a finite reference"):
        food.absolute(None)
    with pytest.raises(ValueError, match="needs a finite reference"):
        food.absolute(math.nan)
    rho = smallest_effect("C9", "rho")
    assert rho.absolute() == rho.absolute(123.0) == 0.1


@pytest.mark.parametrize("fields", [
    {"delta": 0.0}, {"delta": -0.1}, {"delta": math.nan}, {"delta": math.inf}, {"source": "hunch"}, {"why": " "},
    {"relative_to": "control mean"}, {"at_least": 1.0}, {"relative_to": REFERENCE_MEDIAN, "at_least": -1.0}])
def test_an_entry_without_a_positive_argued_delta_is_refused(fields):
    base = {"delta": 0.1, "relative_to": None, "units": "Spearman rho", "source": "domain", "why": "Small."}
    with pytest.raises(ValueError):
        SmallestEffect(**{**base, **fields})


# ------------------------------------------------------------------ the docs' table
SECTION = re.compile(r"^## Smallest effects of interest \{#smallest-effects\}\n(?P<body>.*?)(?=^## )", re.M | re.S)
ROW = re.compile(r"^\| \[(?P<claim>C\d+)\]\(#(?P<anchor>c\d+)\) \| `(?P<part>[^`]+)` \| (?P<rest>.*) \|$")


def docs_table() -> list[tuple[str, ...]]:
    """The rows of the table of docs/claims/index.md#smallest-effects: (claim, part, delta, units, source, why)."""
    section = SECTION.search((REPO / "docs/claims/index.md").read_text())
    assert section, "docs/claims/index.md has no section 'Smallest effects of interest {#smallest-effects}'"
    rows = []
    for line in section["body"].splitlines():
        if line.startswith("| [C"):
            m = ROW.match(line)
            assert m and m["anchor"] == m["claim"].lower(), line
            rows.append((m["claim"], m["part"], *(cell.strip() for cell in m["rest"].split(" | "))))
    return rows


def test_the_docs_table_lists_exactly_the_smallest_effects_in_order():
    shown = docs_table()
    assert all(len(row) == 6 for row in shown), [row for row in shown if len(row) != 6]
    expected = [(c, p, e.shown, e.units, e.source, e.why) for (c, p), e in SMALLEST_EFFECTS.items()]
    assert [row[:2] for row in shown] == [row[:2] for row in expected]
    assert shown == expected


def test_the_shown_delta_is_its_value():
    assert SMALLEST_EFFECTS["C6", "ate"].shown == "4.15"
    assert SMALLEST_EFFECTS["C17", "growth larger with K than without"].shown == "0.333"
    assert SMALLEST_EFFECTS["C10", "group food, M off"].shown == "20% of the reference median, at least 1"
    assert SMALLEST_EFFECTS["C21", "far > near"].shown == "20% of the reference median"
