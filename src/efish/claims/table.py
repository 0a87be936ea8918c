"""A run's claims: every claim of :data:`~efish.claims.registry.CLAIMS` computed from the run's tables.

:func:`claims_and_parts` gives the claims table (one row per claim,
:data:`~efish.claims.verdicts.ROW_COLUMNS`) and the parts table (one row per
part, :data:`~efish.claims.verdicts.PART_COLUMNS`) from one computation; a table
the run lacks makes the parts that read it ``not run``, never an exception.
"""

from __future__ import annotations

from collections.abc import Iterable
from pathlib import Path

import pandas as pd

from ..config.schema import EfishConfig
from ..io import read_parquet
from .registry import CLAIMS
from .verdicts import PART_COLUMNS, ROW_COLUMNS, part_rows

__all__ = ["claims_and_parts", "claims_table", "read_claim_tables"]


def read_claim_tables(results: str | Path, paths: Iterable[str]) -> dict[str, pd.DataFrame]:
    """The tables among ``paths`` that exist under ``results`` (a missing one is simply absent)."""
    results = Path(results)
    return {p: read_parquet(results / p, p) for p in paths if (results / p).is_file()}


def claims_and_parts(results: str | Path, cfg: EfishConfig,
                     claims: Iterable[str] | None = None) -> tuple[pd.DataFrame, pd.DataFrame]:
    """The claims table (one row per claim, :data:`ROW_COLUMNS`) and the parts table (one row per part of each
    claim, :data:`PART_COLUMNS`) of all of CLAIMS, or ``claims``, from the tables under ``results``
    (``results/{run}``): each claim is computed once and both tables come from that computation."""
    chosen = list(CLAIMS) if claims is None else list(claims)
    if unknown := [c for c in chosen if c not in CLAIMS]:
        raise ValueError(f"unknown claims {unknown}: choose among {', '.join(CLAIMS)}")
    tables = read_claim_tables(results, {t for c in chosen for t in CLAIMS[c].tables})
    rows, parts = [], []
    for c in chosen:
        row, found = CLAIMS[c].assess({t: tables[t] for t in CLAIMS[c].tables if t in tables}, cfg)
        rows.append(row)
        parts += part_rows(c, found)
    return (pd.DataFrame(rows, columns=ROW_COLUMNS).astype({"n": "int64"}),
            pd.DataFrame(parts, columns=PART_COLUMNS).astype({"n": "int64", "family": "int64", "sign": "float64",
                                                                  "decides": bool}))


def claims_table(results: str | Path, cfg: EfishConfig, claims: Iterable[str] | None = None) -> pd.DataFrame:
    """One row per claim (all of CLAIMS, or ``claims``) from the tables under ``results`` (``results/{run}``)."""
    return claims_and_parts(results, cfg, claims)[0]
