"""``efish bench group``: a row per group size, both timings positive, and one clear error for bad sizes."""

from __future__ import annotations

import json

import pytest

from efish.bench.group import bench_group, format_group
from efish.cli import main
from efish.config import compose


def test_a_row_per_group_size_with_both_timings():
    rows = bench_group(compose(["scale=smoke", "bench.repeats=1"]), ["scale=smoke"], sizes=[1, 2], episodes=2,
                       steps=5)
    assert [r["policies"] for r in rows] == [1, 2]
    for r in rows:
        assert r["alone_s"] > 0 and r["grouped_s"] > 0
        assert r["speedup"] == pytest.approx(r["alone_s"] / r["grouped_s"])
        assert r["grouped_env_steps_per_s"] == pytest.approx(r["policies"] * 2 * 5 / r["grouped_s"])
        assert r["hidden"] == 16 and r["cpu"] and r["assay"] == "patchy4"
    assert "speed-up" in format_group(rows)


def test_the_command_prints_json_and_refuses_bad_sizes(capsys):
    assert main(["bench", "group", "scale=smoke", "bench.repeats=1", "--sizes", "2", "--episodes", "1",
                 "--steps", "3", "--json"]) == 0
    rows = json.loads(capsys.readouterr().out)
    assert len(rows) == 1 and rows[0]["policies"] == 2
    assert main(["bench", "group", "scale=smoke", "--sizes", "0"]) == 2
    assert "group sizes >= 1" in capsys.readouterr().err
