"""``efish analyze``: tables, the analysis settings it ran with, config.yaml and provenance.json, or one line and
nothing written."""

from __future__ import annotations

import json

import pandas as pd
import pytest

from efish.analysis.registry import get
from efish.cli import main
from efish.config.recorded import recorded_settings

from .helpers import rollout_tables


@pytest.fixture(scope="module")
def assay_folder(tmp_path_factory):
    """An assay's folder of synthetic rollout tables, with a hidden.parquet."""
    folder = tmp_path_factory.mktemp("assay")
    for name, df in rollout_tables(episodes=2, steps=80).items():
        df.to_parquet(folder / f"{name}.parquet", index=False)
    return folder


@pytest.mark.parametrize("name", ["behaviour", "dynamics"])
def test_analyze_writes_tables_settings_config_and_provenance(name, assay_folder, tmp_path, capsys):
    out = tmp_path / name
    assert main(["analyze", name, "scale=smoke", "analysis.seed=3", "analysis.claims_near_cm=12.5",
                 "--tables", str(assay_folder), "--out", str(out)]) == 0
    written = {p.name for p in out.iterdir()}
    assert written == {f"{t}.parquet" for t in get(name).written} | {"config.yaml", "provenance.json"}
    assert "analysis_settings.parquet" in written and "seed: 3" in (out / "config.yaml").read_text()
    settings = recorded_settings(pd.read_parquet(out / "analysis_settings.parquet"))
    assert (settings.seed, settings.claims_near_cm) == (3, 12.5)  # the settings it ran with, overrides and all
    prov = json.loads((out / "provenance.json").read_text())
    assert prov["analysis"] == name and prov["overrides"] == ["scale=smoke", "analysis.seed=3",
                                                              "analysis.claims_near_cm=12.5"]
    assert prov["tables"] == str(assay_folder)
    assert len(pd.read_parquet(out / f"{get(name).outputs[0]}.parquet")) > 0
    assert f"to {out}" in capsys.readouterr().out


def test_the_same_command_gives_the_same_tables(assay_folder, tmp_path):
    for run in ("a", "b"):
        assert main(["analyze", "dynamics", "--tables", str(assay_folder), "--out", str(tmp_path / run)]) == 0
    for table in get("dynamics").outputs:
        pd.testing.assert_frame_equal(pd.read_parquet(tmp_path / f"a/{table}.parquet"),
                                      pd.read_parquet(tmp_path / f"b/{table}.parquet"))


@pytest.mark.parametrize("args, message", [
    (["behaviour"], "episodes.parquet, "),  # and food.parquet: the message names every missing table
    (["nope"], "unknown analysis 'nope'"),
    (["behaviour", "analysis.rate_bins=0"], "analysis.rate_bins=0 is out of range"),
])
def test_bad_input_is_one_line_exit_2_and_nothing_written(args, message, assay_folder, tmp_path, capsys):
    tables = tmp_path / "tables"
    tables.mkdir()
    for name in ("steps", "conditions"):  # no episodes table
        (tables / f"{name}.parquet").write_bytes((assay_folder / f"{name}.parquet").read_bytes())
    out = tmp_path / "out"
    assert main(["analyze", *args, "--tables", str(tables), "--out", str(out)]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and err.startswith("efish: error:") and message in err, err
    assert not out.exists()
