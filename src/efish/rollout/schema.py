"""Every column of every rollout table, declared once (DESIGN "Tables").

Columns are snake_case with units in the name where they have one. Tables are
validated against these schemas before they are written; readers can rely on
names, order and types.
"""

from __future__ import annotations

import pandas as pd
import pyarrow as pa

KEYS_EPISODE = [("condition", pa.string()), ("episode", pa.int32())]

STEPS = pa.schema(KEYS_EPISODE + [
    ("t", pa.int32()), ("t_ms", pa.float64()), ("agent", pa.int16()),
    ("x_cm", pa.float32()), ("y_cm", pa.float32()), ("heading_rad", pa.float32()), ("size", pa.float32()),
    ("move", pa.float32()), ("turn", pa.float32()), ("eod", pa.bool_()), ("bite", pa.bool_()),
    ("ate", pa.bool_()), ("bit", pa.bool_()), ("was_bitten", pa.bool_()), ("collided", pa.bool_()),
    ("reward", pa.float32()),
    ("terminated", pa.bool_()), ("success", pa.bool_()),  # this step ended the episode by the task's rule / reached its goal
    ("dist_agent_cm", pa.float32()), ("bearing_agent_rad", pa.float32()),
    ("dist_food_cm", pa.float32()), ("bearing_food_rad", pa.float32()),
    ("dist_wall_cm", pa.float32()), ("bearing_wall_rad", pa.float32()),
    ("morm_abs_mean", pa.float32()), ("amp_abs_mean", pa.float32()), ("knollen_spikes", pa.int16()),
])

EPISODES = pa.schema(KEYS_EPISODE + [
    ("agent", pa.int16()), ("size", pa.float32()), ("food_eaten", pa.int32()), ("eod_probability", pa.float32()),
    ("bites_given", pa.int32()), ("bites_received", pa.int32()), ("mean_nn_dist_cm", pa.float32()),
    ("return", pa.float32()), ("steps", pa.int32()),  # both up to the episode's end
    ("terminated", pa.bool_()), ("success", pa.bool_()),
])

FOOD = pa.schema(KEYS_EPISODE + [
    ("pellet", pa.int32()), ("x_cm", pa.float32()), ("y_cm", pa.float32()), ("t_spawned", pa.int32()),
    ("t_eaten", pa.int32()),  # -1: never eaten
])

SCHEMAS = {"steps": STEPS, "episodes": EPISODES, "food": FOOD}


def to_table(df: pd.DataFrame, name: str) -> pa.Table:
    """The frame as an Arrow table of schema ``name``; one clear error if a column is missing or extra."""
    schema = SCHEMAS[name]
    missing = [f.name for f in schema if f.name not in df.columns]
    extra = [c for c in df.columns if c not in schema.names]
    if missing or extra:
        raise ValueError(f"table {name!r}: missing columns {missing}, unexpected columns {extra}")
    return pa.Table.from_pandas(df[schema.names], schema=schema, preserve_index=False)


def check_file(path, name: str) -> None:
    """Raise ValueError unless the Parquet file at ``path`` has exactly schema ``name``."""
    import pyarrow.parquet as pq

    got = pq.read_schema(path)
    want = SCHEMAS[name]
    if not got.remove_metadata().equals(want):
        raise ValueError(f"{path} does not match schema {name!r}: {got.names} vs {want.names}")
