"""Write rollout tables atomically, validated against :mod:`efish.rollout.schema`."""

from __future__ import annotations

import os
from contextlib import ExitStack
from pathlib import Path

import pandas as pd
import pyarrow.parquet as pq

from ..io import atomic_path
from .schema import to_table


def write_tables(tables: dict[str, pd.DataFrame], folder: str | Path) -> list[Path]:
    """``<folder>/<name>.parquet`` for every table.

    All are validated, then all are written to temporary files, and only when
    every write succeeded are they renamed into place: a failing write (a full
    disk) leaves the folder as it was, never a half-written table nor a new
    table beside old ones.
    """
    folder = Path(folder)
    arrow = {name: to_table(df, name) for name, df in tables.items()}
    with ExitStack() as stack:
        staged = {}
        for name, table in arrow.items():
            tmp = stack.enter_context(atomic_path(folder / f"{name}.parquet", commit=False))
            pq.write_table(table, tmp)
            staged[name] = tmp
        for name, tmp in staged.items():
            os.replace(tmp, folder / f"{name}.parquet")
    return [folder / f"{name}.parquet" for name in arrow]
