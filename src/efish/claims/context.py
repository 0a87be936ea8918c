"""What a claim is and what its parts share: :class:`Claim`, the :func:`claim` decorator, :class:`Context`.

A claim module (``fig2`` .. ``fig6``) defines each claim as a function of a
:class:`Context` that returns the claim's :class:`~efish.claims.verdicts.Part`
list, decorated with :func:`claim` (its id, panel, statement and the tables it
reads), which makes it a :class:`Claim`. Defining a claim registers nothing:
:mod:`efish.claims.registry` lists them, in the paper's order.

A table the run lacks (:class:`MissingTable`) or data a test cannot use
(ValueError) makes a part ``not run`` with the reason, never an exception:
:func:`evaluate` runs one part, :meth:`Claim.parts` the whole claim.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Callable, Iterable, Mapping
from dataclasses import dataclass, field

import numpy as np
import pandas as pd

from ..config.recorded import recorded_conditions
from ..config.schema import EfishConfig
from ..layout import assay_table, parse_table
from .deltas import smallest_effect
from .statistics import bootstrap_ci
from .verdicts import MIN_UNITS, Outcome, Part, combine, decide_outcome, interval_level

#: ``ci_method`` of an interval no test inverts: every such interval resamples episodes (:meth:`Context.ci`).
BOOTSTRAP = "bootstrap percentile over episodes"
#: A claim's input: table path under ``results/{run}/`` -> the table.
Tables = Mapping[str, pd.DataFrame]


class MissingTable(LookupError):
    """A table a claim needs is not in the results folder; the message names it and its assay."""

    def __init__(self, path: str):
        table = parse_table(path)
        what = (path if table is None else f"assay {table.assay}" if table.kind == "assays"
                else f"analysis {table.analysis} of assay {table.assay}")
        super().__init__(f"needs {path}, which this run lacks ({what} has not run at this scale)")


def evaluate(label: str, statistic: str, compute: Callable[[], Outcome], alpha: float, decides: bool = True,
             claim: str = "") -> Part:
    """Run one part: a missing table or degenerate data (ValueError) is a ``not run`` part whose reason says why.

    The part is decided against its smallest effect of interest (``claim``'s
    delta for ``label``, :func:`efish.claims.deltas.smallest_effect`, scaled by
    the outcome's ``reference`` where it is relative) by
    :func:`~efish.claims.verdicts.decide_outcome`. Fewer than
    :data:`~efish.claims.verdicts.MIN_UNITS` units is ``not run``.
    """
    try:
        out = compute()
    except (MissingTable, ValueError) as exc:
        return Part(label, statistic, reason=str(exc).strip("'\""), decides=decides)
    except KeyError as exc:  # a table from an older run without a column this claim reads
        return Part(label, statistic, reason=f"a table lacks the column or key {exc}", decides=decides)
    smallest = smallest_effect(claim, label)
    reference = float(out.reference)
    delta = (smallest.absolute(reference) if smallest.relative_to is None or np.isfinite(reference)
             else np.nan)
    base = Part(label, statistic, float(out.effect), tuple(map(float, out.ci)), int(out.n), float(out.p),
                decides=decides, sign=out.sign,
                ci_method=out.ci_method or (BOOTSTRAP if np.isfinite(out.ci).all() else ""),
                family=int(out.family), p_floor=float(out.p_floor), reference=reference, delta=float(delta))

    def judged(verdict: str, *why: str, p_opposite: float = np.nan) -> Part:
        return dataclasses.replace(base, verdict=verdict, reason="; ".join(r for r in why if r),
                                   p_opposite=p_opposite)
    if out.verdict is not None:
        return judged(out.verdict, out.reason)
    if out.n < MIN_UNITS:
        return judged("not run", f"n = {out.n}: a test needs at least {MIN_UNITS} units", out.reason)
    if not (np.isfinite(out.effect) and np.isfinite(out.p)):
        return judged("not run", out.reason or "no test result")
    if not np.isfinite(delta):
        return judged("not decidable", f"no finite {smallest.relative_to} for a delta of {smallest.shown}",
                      out.reason)
    verdict, why, p_opposite = decide_outcome(out, delta, alpha)
    return judged(verdict, why, out.reason, p_opposite=p_opposite)


@dataclass
class Context:
    """What a claim's parts share: its tables, the config (the claims' own settings, ``cfg.analysis``), the claim's
    own seeded generator. What the run simulated (a condition's frame rate, sizes, roles) is read from the record
    of the assay (:meth:`recorded`), never from ``cfg``."""

    claim: str
    tables: Tables
    cfg: EfishConfig
    rng: np.random.Generator = field(init=False)

    def __post_init__(self):
        # the claim's number joins the seed, so a claim's draws do not depend on which claims ran before it
        self.rng = np.random.default_rng([self.cfg.analysis.claims_seed, int(self.claim[1:])])

    def table(self, path: str) -> pd.DataFrame:
        """The table at ``path``; :class:`MissingTable` (a ``not run`` part) when the run lacks it."""
        if path not in self.tables:
            raise MissingTable(path)
        return self.tables[path]

    def recorded(self, assay: str) -> Mapping[str, EfishConfig]:
        """The conditions ``assay`` recorded, in its order (``assays/<assay>/conditions.parquet``, which the claim
        names among its tables; :func:`efish.config.recorded.recorded_conditions`)."""
        path = assay_table(assay, "conditions")
        return recorded_conditions(self.table(path), path)

    def ci(self, data: pd.DataFrame, stat: Callable[[pd.DataFrame], float], units_: Iterable[str] = ("episode",),
           strata: str | None = "condition", resamples: int | None = None) -> tuple[float, float]:
        """Bootstrap interval of ``stat`` over episodes (within each condition) at the parts' level (:meth:`level`),
        seeded per claim."""
        strata = strata if strata in data.columns else None
        n = self.cfg.analysis.claims_resamples if resamples is None else resamples
        return bootstrap_ci(data, stat, list(units_), n, self.rng, strata, self.level())

    def part(self, label: str, statistic: str, compute: Callable[[], Outcome], decides: bool = True) -> Part:
        return evaluate(label, statistic, compute, self.cfg.analysis.claims_alpha, decides, self.claim)

    def level(self, family: int = 1) -> float:
        """The level of a part's interval, 1 - 2 alpha / ``family`` (:func:`~efish.claims.verdicts.interval_level`)."""
        return interval_level(self.cfg.analysis.claims_alpha, family)


@dataclass(frozen=True)
class Claim:
    """A claim of the paper (docs/claims/index.md): id, figure panels, statement, the tables it reads (paths under
    ``results/{run}/``) and its computation (a :class:`Context` -> its parts).

    :meth:`assess` gives the claim's row and its parts from one computation; :meth:`run` the row alone.
    """

    id: str
    panel: str
    statement: str
    tables: tuple[str, ...]
    compute: Callable[[Context], list[Part]]

    def parts(self, tables: Tables, cfg: EfishConfig) -> list[Part]:
        """The claim's parts from ``tables``; one ``not run`` part when the claim cannot even be set up."""
        try:
            return self.compute(Context(self.id, tables, cfg))
        except (MissingTable, ValueError) as exc:
            return [Part(self.id, self.statement, reason=str(exc))]

    def assess(self, tables: Tables, cfg: EfishConfig) -> tuple[dict, list[Part]]:
        """The claim's row (:data:`~efish.claims.verdicts.ROW_COLUMNS`, :func:`~efish.claims.verdicts.combine`) and
        the parts it combines."""
        found = self.parts(tables, cfg)
        return combine(self.id, self.panel, found, cfg.analysis.claims_alpha), found

    def run(self, tables: Tables, cfg: EfishConfig) -> dict:
        """The claim's row (:data:`~efish.claims.verdicts.ROW_COLUMNS`)."""
        return self.assess(tables, cfg)[0]


def claim(cid: str, panel: str, statement: str, tables: Iterable[str]) -> Callable[[Callable[[Context], list[Part]]],
                                                                                  Claim]:
    """Decorator: ``compute(ctx) -> [Part]`` becomes the :class:`Claim` ``cid`` (listed by
    :mod:`efish.claims.registry`, not here)."""
    def make(compute: Callable[[Context], list[Part]]) -> Claim:
        return Claim(cid, panel, statement, tuple(tables), compute)
    return make
