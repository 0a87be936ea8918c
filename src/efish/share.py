"""What the points of a sweep share: a stage whose config is the same in two points is built once.

A sweep (:mod:`efish.sweep`) makes one run folder per point. Where two points' configs agree on everything a stage
depends on, the first point (in grid order) builds the stage and every later one gets a copy of its files, so each
folder stays a complete, normal run while the work is done once. A rule belongs to a stage when all its outputs are
the stage's files (:func:`stage_of`); a later point gets all the outputs of such a job at once (the workflow's
``share_<rule>``), and every policy's training even where nothing of its own reads it. The stages:

- ``training``: every policy's training (``train/<seed or recipe>/``: final.pt, metrics.parquet, the kept stages),
  shared where :func:`efish.config.schema.training_config` of every policy recipe is the same: what a training
  checkpoint records and compares, so a sweep over any assay, analysis or scale size key trains each seed once;
- ``rollouts``: everything the analyses read and nothing reads the analysis settings for: each seed's selection
  episodes, every assay's tables (the run's, the top seeds' and the training stages' copies), the top seeds' stacked
  episodes, the scenes, the benchmarks and the clips; shared where the whole config but its ``analysis`` group is
  the same, so a sweep over an analysis or claims key reruns only the analyses, the claims and the figures.

A copied file keeps its provenance: the config.yaml and provenance.json beside it (its own
``<name>.provenance.json`` where it has one) are copied too, so they say how it was made. The copies are plain
copies, not hard links: Snakemake touches the files a job made, and a hard link shares its time with the file it
links, so the source run's own later jobs would look out of date.
"""

from __future__ import annotations

import dataclasses
import json
import re
import shutil
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from pathlib import Path

from .config.schema import training_config
from .io import atomic_path
from .layout import (
    FIGURES_ROOT,
    RESULTS_ROOT,
    Run,
    assay_table,
    bench_file,
    scene_table,
    selection_table,
    stacked_seeds_table,
    stage_copy,
    top_seed_copy,
    training_file,
)
from .run_plan import RunPlan, composed

_RUN = Run("RUN")
# A rule's output pattern (wildcard constraints stripped) under a run's results or figures folder: its relative path.
_UNDER_RUN = re.compile(rf"(?:{re.escape(str(RESULTS_ROOT))}|{re.escape(str(FIGURES_ROOT))})/\{{run\}}/(.+)")
_WILDCARD = re.compile(r"\\\{[a-z]+\\\}")  # a {name} of a layout template, once escaped


def pattern(*templates: str) -> str:
    """A regex matching every path of the layout ``templates`` (``{name}`` stands for one path segment)."""
    return "|".join(_WILDCARD.sub(r"[^/]+", re.escape(t)) for t in templates)


def training_key(plan: RunPlan) -> str:
    """What every policy's training depends on in ``plan`` (:func:`training_config` of each recipe)."""
    base = [f"scale={plan.scale}", *plan.overrides]
    return json.dumps({p: training_config(composed([*base, f"policy={p}"])) for p in plan.policy_recipes},
                      sort_keys=True, default=str)


def rollouts_key(plan: RunPlan) -> str:
    """``plan``'s whole config but its analysis settings."""
    return json.dumps({k: v for k, v in dataclasses.asdict(plan.cfg).items() if k != "analysis"}, sort_keys=True,
                      default=str)


def _assays_in(copy: str) -> str:
    return f"{copy}/{assay_table('{assay}', '{table}')}" if copy else assay_table("{assay}", "{table}")


@dataclass(frozen=True)
class SharedStage:
    """A stage points may share: its name, what it depends on, and the regex of its files (relative to a run's
    results and figures folders)."""

    name: str
    key: Callable[[RunPlan], str]
    results: str
    figures: str = ""

    def sources(self, plans: Sequence[RunPlan]) -> dict[str, str]:
        """Run -> the run it copies this stage from, for every point an earlier point's stage serves."""
        first: dict[str, str] = {}
        borrowed = {}
        for plan in plans:
            owner = first.setdefault(self.key(plan), plan.run)
            if owner != plan.run:
                borrowed[plan.run] = owner
        return borrowed

    @property
    def paths(self) -> str:
        """One regex of every file of the stage under a run's results or figures folder."""
        return "|".join(p for p in (self.results, self.figures) if p)


STAGES = (
    SharedStage("training", training_key, pattern(training_file("{name}", "{file}"))),
    SharedStage("rollouts", rollouts_key,
                pattern(selection_table("{seed}", "{table}"), _assays_in(""), _assays_in(top_seed_copy("{seed}")),
                        _assays_in(stage_copy("{k}")), stacked_seeds_table("{assay}"), scene_table("{scene}"),
                        bench_file("{name}")),
                pattern(str(_RUN.bench_figure("{name}", "{ext}").relative_to(_RUN.figures)),
                        str(_RUN.clip("{assay}").relative_to(_RUN.figures)))),
)


def stage_of(outputs: Sequence[str]) -> SharedStage | None:
    """The stage a rule belongs to: the one whose files all its ``outputs`` are (patterns without wildcard
    constraints, e.g. ``results/{run}/assays/{assay}/steps.parquet``); None for a rule of no stage or of several."""
    found = set()
    for path in outputs:
        under = _UNDER_RUN.fullmatch(path)
        found.add(next((s for s in STAGES if under and re.fullmatch(s.paths, under[1])), None))
    return found.pop() if len(found) == 1 else None


def provenance_of(path: Path) -> list[Path]:
    """The files that say how ``path`` was made: its folder's config.yaml and its own provenance record (or its
    folder's), those that exist."""
    own = path.with_name(f"{path.stem}.provenance.json")
    record = own if own.is_file() else path.with_name("provenance.json")
    return [p for p in (path.with_name("config.yaml"), record) if p.is_file()]


def copy_shared(source: str | Path, target: str | Path) -> None:
    """Copy a shared stage's file ``source`` to ``target`` with its provenance (:func:`provenance_of`), each written
    atomically (jobs copying into one folder at once each write whole files)."""
    source, target = Path(source), Path(target)
    target.parent.mkdir(parents=True, exist_ok=True)
    for path in [source, *provenance_of(source)]:
        with atomic_path(target.parent / path.name) as tmp:
            shutil.copyfile(path, tmp)


def copy_job(sources: Sequence[str], targets: Sequence[str], log: str | Path) -> None:
    """A share job: each of ``sources`` to the target in the same place (:func:`copy_shared`), and what was copied
    into ``log``."""
    for source, target in zip(sources, targets, strict=True):
        copy_shared(source, target)
    Path(log).write_text("".join(f"copied {source}\n" for source in sources))
