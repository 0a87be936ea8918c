"""Verdicts across seeds: seed_verdicts, seeds_agree and the flip sentence, on synthetic tables."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

from efish.claims.seeds import agreement, flip_sentence, with_seed_verdicts
from efish.claims.verdicts import ROW_COLUMNS


def table(verdicts: dict[str, str], reason: str = "") -> pd.DataFrame:
    """A claims table (ROW_COLUMNS) with the given verdict per claim."""
    n = len(verdicts)
    return pd.DataFrame({"claim": list(verdicts), "panel": ["2B"] * n, "statistic": ["a test"] * n,
                         "effect": np.linspace(0.1, 0.5, n), "ci_low": [0.0] * n, "ci_high": [1.0] * n,
                         "n": [8] * n, "p": [0.01] * n, "verdict": list(verdicts.values()),
                         "parts": [f"1 {v}" for v in verdicts.values()], "reason": [reason] * n},
                        columns=ROW_COLUMNS)


def test_agreeing_seeds_count_and_keep_the_reason():
    sel = table({"C1": "holds", "C2": "opposite"}, reason="why")
    out = with_seed_verdicts(sel, {1: table({"C1": "holds", "C2": "opposite"}),
                                   7: table({"C1": "holds", "C2": "opposite"})}, selected_seed=3)
    assert list(out.columns) == [*ROW_COLUMNS[:-1], "seed_verdicts", "seeds_agree", "reason"]
    assert out["seed_verdicts"].tolist() == ["seed 3: holds; seed 1: holds; seed 7: holds",
                                             "seed 3: opposite; seed 1: opposite; seed 7: opposite"]
    assert out["seeds_agree"].tolist() == ["3/3 hold", "3/3 opposite"]
    assert out["reason"].tolist() == ["why", "why"]
    pd.testing.assert_frame_equal(out[ROW_COLUMNS], sel)  # the selected seed's numbers and verdicts stay


def test_a_flip_is_counted_and_said_in_the_reason():
    sel = table({"C1": "holds", "C2": "absent"}, reason="the paper's sign")
    out = with_seed_verdicts(sel, {1: table({"C1": "absent", "C2": "absent"}),
                                   7: table({"C1": "holds", "C2": "not decidable"})}, selected_seed=3)
    row = out.set_index("claim").loc["C1"]
    assert row["verdict"] == "holds" and row["seed_verdicts"] == "seed 3: holds; seed 1: absent; seed 7: holds"
    assert row["seeds_agree"] == "2/3 hold, 1/3 absent"
    assert row["reason"] == ("the paper's sign. The verdict flips between seeds: holds at seeds 3 (selected), 7; "
                             "absent at seed 1.")
    c2 = out.set_index("claim").loc["C2"]
    assert c2["seeds_agree"] == "2/3 absent, 1/3 not decidable" and "flips between seeds" in c2["reason"]


def test_seeds_where_a_claim_did_not_run_are_not_counted():
    sel = table({"C1": "holds", "C4": "holds", "C5": "not run"}, reason="")
    other = {1: table({"C1": "not run", "C4": "holds", "C5": "holds"}), 7: table({"C1": "not run", "C4": "not run"})}
    out = with_seed_verdicts(sel, other, selected_seed=3).set_index("claim")
    assert out.loc["C1", "seeds_agree"] == "1/1 hold (other seeds: not run)"
    assert out.loc["C1", "seed_verdicts"] == "seed 3: holds; seed 1: not run; seed 7: not run"
    assert out.loc["C4", "seeds_agree"] == "2/2 hold (seed 7: not run)"
    assert out.loc["C5", "seeds_agree"] == "1/1 hold (seeds 3, 7: not run)"  # C5 is absent from seed 7's table
    assert out.loc["C5", "verdict"] == "not run"
    assert (out["reason"] == "").all()  # not run is no flip


def test_no_other_seed_is_the_selected_seed_alone():
    sel = table({"C1": "holds", "C2": "absent", "C3": "not run"})
    out = with_seed_verdicts(sel, {}, selected_seed=2)
    assert out["seeds_agree"].tolist() == ["1/1 hold", "1/1 absent", "not run (0/1 seeds ran)"]
    assert out["seed_verdicts"].tolist() == ["seed 2: holds", "seed 2: absent", "seed 2: not run"]


def test_rerunning_on_its_own_output_replaces_the_columns():
    sel = table({"C1": "holds"})
    once = with_seed_verdicts(sel, {1: table({"C1": "holds"})}, selected_seed=3)
    again = with_seed_verdicts(once, {1: table({"C1": "holds"})}, selected_seed=3)
    pd.testing.assert_frame_equal(once, again)


def test_helpers_read_a_mapping_selected_seed_first():
    assert agreement({3: "opposite", 1: "holds"}) == "1/2 hold, 1/2 opposite"
    assert agreement({3: "not run", 1: "not run"}) == "not run (0/2 seeds ran)"
    assert flip_sentence({3: "holds", 1: "holds", 7: "not run"}) == ""


@pytest.mark.parametrize("others, message", [
    ({3: table({"C1": "holds"})}, "is the selected seed"),
    ({1: table({"C1": "maybe"})}, "has verdicts ['maybe']"),
    ({1: table({"C1": "holds"}).drop(columns="verdict")}, "has no column verdict"),
    ({1: pd.concat([table({"C1": "holds"})] * 2)}, "lists claims ['C1'] twice"),
])
def test_bad_tables_are_one_clear_error(others, message):
    with pytest.raises(ValueError, match=message.replace("[", r"\[").replace("]", r"\]")):
        with_seed_verdicts(table({"C1": "holds"}), others, selected_seed=3)


def test_the_claims_page_shows_seeds_agree_beside_the_verdict_when_the_table_has_it():
    from efish.claims.report import claims_markdown

    sel = table({"C1": "holds"})
    page = claims_markdown(with_seed_verdicts(sel, {1: table({"C1": "opposite"})}, selected_seed=3), "header")
    assert "| verdict | parts | seeds_agree | reason |" in page and "| holds | 1 holds | 1/2 hold, 1/2 opposite |" in page
    assert "seeds_agree" not in claims_markdown(sel, "header")
