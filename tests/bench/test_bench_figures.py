"""``efish bench accuracy|scaling`` write their table to --out and their figure to --figures (by default the run's
results/<run>/bench and figures/<run>/bench); ``efish figure bench/<name>`` redraws the figure from the table."""

from __future__ import annotations

import json

import pandas as pd
import pytest

from efish.cli import main
from efish.config import run_name
from efish.layout import Run

SIZES = {
    # the default kernels (float64, image order 1, softening 1e-5): nothing compiled for this test alone
    "accuracy": ["bench.scenes=2", "bench.repeats=1", "bench.tolerances=[1e-07]", "bench.image_orders=[1]",
                 "bench.dtypes=[float64]", "bench.softenings_m=[1e-05]"],
    "scaling": ["bench.scaling_sizes_cm=[40.0]", "bench.scaling_crowded_multiplier=0.0", "bench.scaling_agents=[1]",
                "bench.scaling_envs=1", "bench.scaling_agent_steps=8", "bench.scaling_exact_agent_steps=2",
                "bench.reference_rounds=1"],
}


@pytest.mark.parametrize("name", ["accuracy", "scaling"])
def test_the_table_goes_to_the_runs_results_and_the_figure_to_its_figures(name, tmp_path, monkeypatch, capsys):
    monkeypatch.chdir(tmp_path)
    overrides = ["scale=smoke", *SIZES[name]]
    assert main(["bench", name, *overrides]) == 0
    run = Run(run_name("smoke", SIZES[name]))
    table = run.bench / f"bench_{name}.parquet"
    assert len(pd.read_parquet(table)) > 0
    assert {p.name for p in run.bench.iterdir()} == {table.name, f"bench_{name}.provenance.json", "config.yaml"}
    drawn = {p.name for p in run.bench_figures.iterdir()}
    assert drawn == {f"bench_{name}.png", f"bench_{name}.pdf", f"bench_{name}.provenance.json", "config.yaml"}
    assert run.bench_figure(f"bench_{name}", "png").stat().st_size > 0
    prov = json.loads((run.bench_figures / f"bench_{name}.provenance.json").read_text())
    assert prov["table"] == str(table) and prov["overrides"] == overrides
    assert f"wrote {table}" in capsys.readouterr().out

    # efish figure bench/<name> redraws it from the table alone, into <out>/bench/
    again = tmp_path / "again"
    assert main(["figure", f"bench/{name}", "scale=smoke", "--results", str(run.results), "--out", str(again)]) == 0
    assert {p.name for p in (again / "bench").glob("*.p*")} >= {f"bench_{name}.png", f"bench_{name}.pdf"}


def test_explicit_folders_and_a_missing_table(tmp_path, capsys):
    out, figures = tmp_path / "tables", tmp_path / "drawn"
    assert main(["bench", "scaling", *SIZES["scaling"], "--out", str(out), "--figures", str(figures)]) == 0
    assert (out / "bench_scaling.parquet").is_file() and not list(out.glob("*.png"))
    assert (figures / "bench_scaling.png").is_file() and (figures / "bench_scaling.pdf").is_file()
    capsys.readouterr()
    assert main(["figure", "bench/accuracy", "--results", str(tmp_path), "--out", str(tmp_path / "f")]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and "run efish bench accuracy first" in err
    assert not (tmp_path / "f").exists()
    assert main(["figure", "bench/nope", "--results", str(tmp_path), "--out", str(tmp_path / "f")]) == 2
    assert "no benchmark figure 'nope'" in capsys.readouterr().err
