"""Write rollout tables atomically, validated against :mod:`efish.rollout.schema`."""

from __future__ import annotations

from pathlib import Path

import pandas as pd

from ..io import write_parquet_tables
from .schema import to_table


def write_tables(tables: dict[str, pd.DataFrame], folder: str | Path) -> list[Path]:
    """``<folder>/<name>.parquet`` for every table.

    All are validated, then written all or none (:func:`efish.io.write_parquet_tables`):
    a failing write (a full disk) leaves the folder as it was, never a
    half-written table nor a new table beside old ones.
    """
    return write_parquet_tables({name: to_table(df, name) for name, df in tables.items()}, folder)
