"""``table_digest`` (tests/helpers.py), the one way the tests compare whole tables (the SLURM run against the
local run, an assay run twice): equal digests exactly for equal values, whatever the column types."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pyarrow.parquet as pq

from efish.rollout.schema import to_table

from .helpers import conditions_of, table_digest


def lists_table() -> pd.DataFrame:
    return pd.DataFrame({"condition": ["a", "b"], "sizes": [[0.25, 0.75], [0.5]], "roles": [["x", "y"], []],
                         "nested": [[[1, 2], [3]], [[]]], "n": [2, 1]})


def test_list_and_nested_columns_hash_by_their_elements():
    table = lists_table()
    as_arrays = table.assign(sizes=[np.array(v) for v in table["sizes"]], roles=[np.array(v) for v in table["roles"]])
    assert table_digest(table) == table_digest(as_arrays)  # what Parquet reads back: arrays, not lists
    assert table_digest(table) == table_digest(table[table.columns[::-1]])  # column order does not count
    changed = table.assign(sizes=[[0.25, 0.76], [0.5]])
    assert table_digest(changed) != table_digest(table)
    regrouped = table.assign(nested=[[[1], [2, 3]], [[]]])  # same flat elements, other nesting
    assert table_digest(regrouped) != table_digest(table)
    assert table_digest(table.assign(roles=[["x", "y"], [""]])) != table_digest(table)  # [] is not [""]


def test_nan_equals_nan_and_negative_zero_equals_zero():
    table = pd.DataFrame({"x": [0.0, np.nan, 1.5], "y": np.array([-0.0, 2.0, np.nan], np.float32),
                          "l": [[0.0, np.nan], [1.0], []]})
    other_nan = np.frombuffer(np.uint64(0x7FF8000000000001).tobytes(), np.float64)[0]  # a NaN of another payload
    same = pd.DataFrame({"x": [-0.0, other_nan, 1.5], "y": np.array([0.0, 2.0, np.nan], np.float32),
                         "l": [[-0.0, np.nan], [1.0], []]})
    assert table_digest(table) == table_digest(same)
    assert table_digest(table.assign(x=[0.0, 0.0, 1.5])) != table_digest(table)  # NaN is not 0
    assert table_digest(table.assign(y=table["y"].astype(np.float64))) != table_digest(table)  # the dtype counts


def test_ignored_columns_are_left_out_and_rows_count():
    table = pd.DataFrame({"v": [1, 2, 3], "wall_s": [0.1, 0.2, 0.3]})
    assert table_digest(table, ignore={"wall_s"}) == table_digest(table.assign(wall_s=9.0), ignore={"wall_s"})
    assert table_digest(table) != table_digest(table.assign(wall_s=9.0))
    assert table_digest(table) != table_digest(table.iloc[::-1].reset_index(drop=True))
    assert table_digest(table) == table_digest(table.set_index(pd.Index([7, 8, 9])))  # the index does not


def test_a_conditions_table_read_back_from_parquet_hashes_like_the_one_written(tmp_path):
    written = conditions_of("onepatch")
    pq.write_table(to_table(written, "conditions"), tmp_path / "conditions.parquet")
    read = pd.read_parquet(tmp_path / "conditions.parquet")
    assert isinstance(read["overrides"].iloc[0], np.ndarray)  # list columns come back as arrays
    assert table_digest(read) == table_digest(pd.read_parquet(tmp_path / "conditions.parquet"))
    renamed = read.copy()
    renamed.at[0, "roles"] = np.array(["resident", "resident"])
    assert table_digest(renamed) != table_digest(read)
