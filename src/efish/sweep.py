"""Sweeps: a grid of overrides, one run per point, all in one Snakemake call (``--config sweep=...``).

A sweep is a mapping key -> values, given inline (``sweep="train.lr=1e-3,3e-4 analysis.claims_alpha=0.05,0.01"``)
or as a YAML file of the same mapping (``sweep=sweeps/lr.yaml``). Its points are the product of the values, in
the order given; each point's overrides follow the run's own (``overrides=``), and the point is a normal run in the
folder a single run with those overrides gets (:func:`efish.config.run_name`); the sweep resumes as a whole, like
any Snakemake call. A value equal to what the run already has (the scale's own
``analysis.claims_resamples=100`` at smoke) adds no override, so that point is the run without it, whose folder
may already be up to date. Bad input is one line (:class:`efish.run_plan.PlanError`).
"""

from __future__ import annotations

import itertools
import shlex
from collections.abc import Mapping, Sequence
from pathlib import Path

import yaml

from .config import run_name
from .run_plan import CACHE, PlanError, RunPlan, composed, run_settings

#: The YAML file suffixes that make a sweep a file rather than an inline grid.
SWEEP_FILES = (".yaml", ".yml")


def parse_grid(text: str) -> dict[str, list[str]]:
    """``key=v1,v2 other=w1,w2`` -> ``{key: [v1, v2], other: [w1, w2]}`` (shell words; a value with a comma in it,
    such as a list, goes in a sweep file). A word without ``=``, an empty key or value, or a key given twice is a
    :class:`PlanError`."""
    grid: dict[str, list[str]] = {}
    for word in shlex.split(text):
        key, sep, values = word.partition("=")
        listed = values.split(",")
        if not sep or not key or not all(listed):
            raise PlanError(f"sweep: {word!r} is not KEY=VALUE,VALUE,...: e.g. sweep=\"train.lr=1e-3,3e-4\"")
        _add(grid, key, listed)
    if not grid:
        raise PlanError("sweep: no keys: give KEY=VALUE,VALUE,... or a YAML file of key: [values]")
    return grid


def read_grid(path: Path) -> dict[str, list[str]]:
    """A sweep file: a YAML mapping of key -> a list of values (each written as a Hydra override value)."""
    if not path.is_file():
        raise PlanError(f"sweep: no sweep file {path}")
    try:
        mapping = yaml.safe_load(path.read_text())
    except yaml.YAMLError as exc:
        raise PlanError(f"sweep: {path} is not YAML ({str(exc).splitlines()[0]})") from None
    if not isinstance(mapping, dict) or not mapping:
        raise PlanError(f"sweep: {path} must map each key to a list of values, e.g. 'train.lr: [1e-3, 3e-4]'")
    grid: dict[str, list[str]] = {}
    for key, values in mapping.items():
        if not isinstance(values, list) or not values:
            raise PlanError(f"sweep: {path}: {key} needs a non-empty list of values")
        _add(grid, str(key), [_override_value(v) for v in values])
    return grid


def _add(grid: dict[str, list[str]], key: str, values: list[str]) -> None:
    if key in grid:
        raise PlanError(f"sweep: {key} is given twice")
    if len(set(values)) != len(values):
        raise PlanError(f"sweep: {key} lists a value twice")
    grid[key] = values


def _override_value(value: object) -> str:
    """A YAML value as Hydra's override grammar writes it: lists in brackets, booleans lower case, null as null."""
    if isinstance(value, list):
        return "[" + ",".join(_override_value(v) for v in value) + "]"
    return "null" if value is None else str(value).lower() if isinstance(value, bool) else str(value)


def sweep_grid(value: str) -> dict[str, list[str]]:
    """The grid of ``--config sweep=``: a file (its name ends in .yaml or .yml) or an inline grid."""
    text = value.strip()
    return read_grid(Path(text)) if text.endswith(SWEEP_FILES) else parse_grid(text)


def grid_points(grid: Mapping[str, Sequence[str]]) -> list[tuple[str, ...]]:
    """Every point of ``grid``, the product of its values in the order given, as ``key=value`` overrides."""
    return [tuple(f"{k}={v}" for k, v in zip(grid, values, strict=True))
            for values in itertools.product(*grid.values())]


def sweep_overrides(scale: str, overrides: Sequence[str], grid: Mapping[str, Sequence[str]]) -> list[tuple[str, ...]]:
    """Each point's overrides: the run's, then the point's, less each point value the run already has (an override
    that composes to the same config as none). A key the run's overrides also set is a :class:`PlanError`, and so
    are a point that does not compose (an unknown key, a value out of range: efish's one line) and two points in
    one folder (values that compose alike)."""
    if clash := sorted(k for k in grid if any(o.lstrip("+~").split("=", 1)[0] == k for o in overrides)):
        raise PlanError(f"sweep: {', '.join(clash)} also in overrides: sweep a key or set it, not both")
    base = [f"scale={scale}", *overrides]
    plain = composed(base)
    points = []
    for point in grid_points(grid):
        kept = tuple(o for o in point if composed([*base, o]) != plain)
        composed([*base, *kept])  # the point as a whole: one line if its values do not go together
        points.append((*overrides, *kept))
    runs = [run_name(scale, p) for p in points]
    if twice := sorted({run for run in runs if runs.count(run) > 1}):
        raise PlanError(f"sweep: several points are run {', '.join(twice)}: their values compose to the same config")
    return points


def run_plans(config: Mapping[str, object], cache: Path | None = CACHE) -> list[RunPlan]:
    """The plans of Snakemake's ``--config``: one per point of its sweep, in grid order, or the one run without
    ``sweep``; the points must agree on what the rules declare once (:func:`check_alike`)."""
    if "sweep" not in config:
        return [RunPlan.from_config(config, cache)]
    scale, overrides, _ = run_settings(config)
    points = sweep_overrides(scale, overrides, sweep_grid(str(config["sweep"])))
    plans = [RunPlan.from_config({"scale": scale, "overrides": shlex.join(point)}, cache) for point in points]
    check_alike(plans)
    return plans


def check_alike(plans: Sequence[RunPlan]) -> None:
    """The points of one sweep must agree on what the rules declare once for every run: the kept training stages
    (the train rule's outputs) and which assays record the GRU state (which assay rule builds them); else a
    :class:`PlanError` naming the key to sweep in calls of its own."""
    first = plans[0]
    for plan in plans[1:]:
        if plan.stages.kept != first.stages.kept:
            raise PlanError(f"sweep: runs {first.run} and {plan.run} keep different training stages "
                            "(scale.keep_stages): sweep it in separate calls")
        hidden = {a for a in plan.buildable_assays if plan.records_hidden(a)}
        if differ := sorted(hidden ^ {a for a in first.buildable_assays if first.records_hidden(a)}):
            raise PlanError(f"sweep: runs {first.run} and {plan.run} differ in whether {', '.join(differ)} records "
                            "hidden states (assay.record_hidden): sweep it in separate calls")


def sweep_points(scale: str, overrides: Sequence[str], sweep: str) -> list[tuple[str, str]]:
    """(run folder, label) of each point of a sweep, in grid order: the label is the point's values as the grid
    gives them (``analysis.claims_alpha=0.01``, several joined by spaces), what a reader of a table or a heatmap
    of the sweep wants instead of the folder's hash."""
    grid = sweep_grid(sweep)
    points = sweep_overrides(scale, overrides, grid)
    return [(run_name(scale, point), " ".join(values))
            for point, values in zip(points, grid_points(grid), strict=True)]


def sweep_runs(scale: str, overrides: Sequence[str], sweep: str) -> list[str]:
    """The run folders of a sweep, in grid order (what ``efish compare-claims --sweep`` reads)."""
    return [run for run, _ in sweep_points(scale, overrides, sweep)]
