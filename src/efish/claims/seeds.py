"""Verdicts across seeds: the selected seed's claims table with how the other top seeds judged.

One seed at a few episodes per condition cannot carry a verdict alone, so the
pipeline computes every claim for the selected seed and for each of the other
``scale.top_seeds`` best-ranked seeds (``results/{run}/seeds/seed_{n}/claims/``)
and :func:`with_seed_verdicts` adds to the selected seed's table:

- ``seed_verdicts``: each seed's verdict, the selected seed first, then the
  others in the order given (the ranking's): ``"seed 3: holds; seed 1: absent;
  seed 7: holds"``;
- ``seeds_agree``: the verdicts of the seeds where the claim ran, counted over
  those seeds: ``"3/3 hold"``, ``"2/3 hold, 1/3 absent"``. Seeds where it did
  not run are named after the count: ``"1/1 hold (other seeds: not run)"``
  when only the selected seed ran (e.g. a claim on the homing assay, whose
  policies are recipes that do not depend on the seed), ``"2/2 hold (seed 7:
  not run)"`` otherwise; ``"not run (0/3 seeds ran)"`` when no seed ran. The
  counts use the plural verb ``hold`` for *holds*; the other verdicts are
  unchanged. Counts follow the order of
  :data:`VERDICTS`. With no other seed (``scale.top_seeds`` <= 1) it is the
  selected seed's alone: ``"1/1 hold"``.

When the seeds that ran disagree, the ``reason`` gains one sentence saying so,
e.g. ``"The verdict flips between seeds: holds at seeds 3 (selected), 7;
absent at seed 1."``. The other columns (effect, interval, n, p, verdict) stay
the selected seed's.

Pure pandas: it reads tables, never the simulator.
"""

from __future__ import annotations

from collections.abc import Mapping

import pandas as pd

from .verdicts import VERDICTS

__all__ = ["SEED_COLUMNS", "VERDICTS", "agreement", "flip_sentence", "with_seed_verdicts"]

#: The columns :func:`with_seed_verdicts` adds, after ``verdict`` and its ``parts`` tally (before ``reason``).
SEED_COLUMNS = ("seed_verdicts", "seeds_agree")
#: How a verdict reads after a count of seeds ("2/3 hold").
PLURAL = {"holds": "hold", "absent": "absent", "opposite": "opposite", "inconclusive": "inconclusive",
          "not decidable": "not decidable"}


def seed_list(seeds: list[int], selected: int | None = None) -> str:
    """``seed 3`` or ``seeds 3, 7``, the selected seed marked."""
    names = [f"{s} (selected)" if s == selected else str(s) for s in seeds]
    return f"seed{'s' if len(seeds) > 1 else ''} {', '.join(names)}"


def agreement(verdicts: Mapping[int, str]) -> str:
    """``seeds_agree`` for one claim from its verdict per seed (the selected seed first).

    >>> agreement({3: "holds", 1: "absent", 7: "holds"}), agreement({3: "holds", 1: "not run"})
    ('2/3 hold, 1/3 absent', '1/1 hold (other seeds: not run)')
    """
    seeds = list(verdicts)
    ran = [s for s in seeds if verdicts[s] != "not run"]
    if not ran:
        return f"not run (0/{len(seeds)} seeds ran)"
    counts = [f"{sum(verdicts[s] == v for s in ran)}/{len(ran)} {PLURAL[v]}" for v in VERDICTS
              if any(verdicts[s] == v for s in ran)]
    text = ", ".join(counts)
    missing = [s for s in seeds if s not in ran]
    if missing:
        others = missing == seeds[1:]  # the selected seed ran and no other did
        text += " (other seeds: not run)" if others else f" ({seed_list(missing)}: not run)"
    return text


def flip_sentence(verdicts: Mapping[int, str]) -> str:
    """The sentence ``reason`` gains when the seeds that ran disagree ('' when they agree)."""
    selected = next(iter(verdicts), None)
    ran = {s: v for s, v in verdicts.items() if v != "not run"}
    if len(set(ran.values())) < 2:
        return ""
    groups = [f"{v} at {seed_list([s for s in ran if ran[s] == v], selected)}" for v in VERDICTS if v in ran.values()]
    return f"The verdict flips between seeds: {'; '.join(groups)}."


def _append(reason, sentence: str) -> str:
    reason = "" if pd.isna(reason) else str(reason).rstrip()
    if not sentence:
        return reason
    if not reason:
        return sentence
    return f"{reason}{'' if reason.endswith('.') else '.'} {sentence}"


def _verdicts(table: pd.DataFrame, what: str) -> dict[str, str]:
    """claim -> verdict of one seed's claims table, checked against :data:`VERDICTS`."""
    missing = [c for c in ("claim", "verdict") if c not in table.columns]
    if missing:
        raise ValueError(f"{what} has no column {', '.join(missing)}: is it a claims table (efish claims)?")
    if table["claim"].duplicated().any():
        raise ValueError(f"{what} lists claims {sorted(table.loc[table['claim'].duplicated(), 'claim'])} twice")
    if unknown := sorted(set(table["verdict"]) - set(VERDICTS)):
        raise ValueError(f"{what} has verdicts {unknown}: a verdict is one of {', '.join(VERDICTS)}")
    return dict(zip(table["claim"], table["verdict"], strict=True))


def with_seed_verdicts(selected: pd.DataFrame, others: Mapping[int, pd.DataFrame],
                       selected_seed: int) -> pd.DataFrame:
    """The selected seed's claims table with ``seed_verdicts`` and ``seeds_agree`` after ``verdict`` (and ``parts``).

    ``selected``: the selected seed's table (the columns of
    :data:`efish.claims.verdicts.ROW_COLUMNS`); ``others``: the other top
    seeds' tables by seed number, in the order they are to be listed (the
    ranking's). A claim absent from another seed's table counts as ``not run``
    there; claims only another seed has are ignored. A table without a claim or
    verdict column, a claim listed twice, a verdict outside :data:`VERDICTS` or
    the selected seed among ``others`` is a ValueError.
    """
    selected_seed = int(selected_seed)
    others = {int(seed): table for seed, table in others.items()}
    if selected_seed in others:
        raise ValueError(f"seed {selected_seed} is the selected seed: its claims are the main table, not another "
                         "seed's")
    own = _verdicts(selected, f"the selected seed's ({selected_seed}) claims table")
    theirs = {seed: _verdicts(table, f"seed {seed}'s claims table") for seed, table in others.items()}
    per_claim = [{selected_seed: own[c], **{seed: v.get(c, "not run") for seed, v in theirs.items()}}
                 for c in selected["claim"]]
    out = selected.drop(columns=[c for c in SEED_COLUMNS if c in selected.columns]).reset_index(drop=True)
    at = list(out.columns).index("parts" if "parts" in out.columns else "verdict") + 1
    out.insert(at, "seed_verdicts", ["; ".join(f"seed {s}: {v}" for s, v in verdicts.items())
                                     for verdicts in per_claim])
    out.insert(at + 1, "seeds_agree", [agreement(verdicts) for verdicts in per_claim])
    if "reason" in out.columns:
        out["reason"] = [_append(r, flip_sentence(verdicts)) for r, verdicts in zip(out["reason"], per_claim,
                                                                                     strict=True)]
    return out
