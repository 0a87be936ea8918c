"""``efish bench pipeline``: where a pipeline run spent its time, from Snakemake's benchmark files.

Every rule writes ``results/{scale}/benchmarks/<group>/<job>.tsv`` (or
``benchmarks/<job>.tsv``); this module groups them by rule family and sums
wall time, so a user sees what each stage of the DAG costs at a scale.
"""

from __future__ import annotations

from pathlib import Path

import pandas as pd

from ..layout import BENCHMARKS

COLUMNS = ("group", "jobs", "total_s", "max_s", "max_rss_mb")


def job_group(path: Path, root: Path) -> str:
    """Rule family of a benchmark file: its sub-folder (train, selection, assays, figures) or its stem."""
    rel = path.relative_to(root)
    return rel.parts[0] if len(rel.parts) > 1 else rel.stem


def pipeline_timings(results: Path) -> pd.DataFrame:
    """One row per rule family: number of jobs, summed and largest wall time (s), largest resident memory."""
    root = Path(results) / BENCHMARKS
    files = sorted(root.glob("**/*.tsv"))
    if not files:
        raise ValueError(f"no Snakemake benchmark files under {root}: run the pipeline first")
    rows = []
    for path in files:
        bench = pd.read_csv(path, sep="\t")
        rows.append({"group": job_group(path, root), "s": float(bench["s"].iloc[-1]),
                     "max_rss": pd.to_numeric(bench["max_rss"], errors="coerce").iloc[-1]})
    jobs = pd.DataFrame(rows)
    table = jobs.groupby("group").agg(jobs=("s", "size"), total_s=("s", "sum"), max_s=("s", "max"),
                                      max_rss_mb=("max_rss", "max")).reset_index()
    total = pd.DataFrame([{"group": "all", "jobs": len(jobs), "total_s": jobs["s"].sum(), "max_s": jobs["s"].max(),
                           "max_rss_mb": jobs["max_rss"].max()}])
    return pd.concat([table.sort_values("total_s", ascending=False), total], ignore_index=True)[list(COLUMNS)]


def format_timings(table: pd.DataFrame) -> str:
    """The table as aligned text; total_s sums job times, so it exceeds the wall time when jobs ran in parallel."""
    text = table.to_string(index=False, float_format=lambda v: f"{v:,.1f}")
    return text + "\n(total_s sums job wall times; with parallel jobs the pipeline's own wall time is shorter)"
