"""Write rollout tables atomically, validated against :mod:`efish.rollout.schema`."""

from __future__ import annotations

from pathlib import Path

import pandas as pd
import pyarrow.parquet as pq

from ..io import atomic_path
from .schema import to_table


def write_tables(tables: dict[str, pd.DataFrame], folder: str | Path) -> list[Path]:
    """``<folder>/<name>.parquet`` for every table; all are validated before any is written."""
    folder = Path(folder)
    arrow = {name: to_table(df, name) for name, df in tables.items()}
    paths = []
    for name, table in arrow.items():
        path = folder / f"{name}.parquet"
        with atomic_path(path) as tmp:
            pq.write_table(table, tmp)
        paths.append(path)
    return paths
