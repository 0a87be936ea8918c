"""The benchmarks' figures, drawn from their tables: by ``efish bench accuracy|scaling`` after measuring, and again
by ``efish figure bench/accuracy|bench/scaling`` from the table alone. Tables live in ``results/<run>/bench/``,
figures (PNG and PDF) in ``figures/<run>/bench/`` (:mod:`efish.layout`), both named ``bench_<name>``."""

from __future__ import annotations

from pathlib import Path

import pandas as pd

from ..layout import FIGURE_FORMATS, bench_file

NAMES = ("accuracy", "scaling")


def stem(name: str) -> str:
    """``bench_<name>``: the file name (without suffix) of a benchmark's table and of its figure."""
    return f"bench_{name}"


def _plot(name: str):
    if name == "accuracy":
        from .accuracy import plot_accuracy

        return plot_accuracy
    if name == "scaling":
        from .scaling import plot_scaling

        return plot_scaling
    raise ValueError(f"no benchmark figure {name!r}: choose one of {', '.join(NAMES)}")


def draw_bench_figure(name: str, table: pd.DataFrame, folder: Path) -> list[Path]:
    """The figure of benchmark ``name`` (accuracy, scaling) from its table, as ``folder/bench_<name>.png|pdf``."""
    from ..io import atomic_path

    plot, written = _plot(name), []
    for ext in FIGURE_FORMATS:
        path = Path(folder) / f"{stem(name)}.{ext}"
        with atomic_path(path) as tmp:
            plot(table, tmp)
        written.append(path)
    return written


def bench_table_path(name: str, results: Path) -> Path:
    """``<results>/bench/bench_<name>.parquet``: the table ``efish bench <name>`` wrote into a run's folder."""
    return Path(results) / bench_file(f"{stem(name)}.parquet")


def redraw_bench_figure(name: str, results: Path, folder: Path) -> list[Path]:
    """:func:`draw_bench_figure` from the run's table (:func:`bench_table_path`); one clear error without it."""
    from ..io import read_parquet

    _plot(name)  # an unknown name fails before any file is read
    table = bench_table_path(name, results)
    if not table.is_file():
        raise ValueError(f"the {name} figure needs {table}, which does not exist (run efish bench {name} first)")
    return draw_bench_figure(name, read_parquet(table, f"the {name} table"), folder)
