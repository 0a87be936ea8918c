"""The whole pipeline's progress, for ``efish watch``: how many of a run's jobs are done, of how many, and the time
left at the run's own job times (docs/tutorials/watch-a-run.md#the-pipeline-line).

Snakemake's own count ("19 of 78 steps") cannot know the jobs after the select_seed checkpoint until it has run:
at the laptop scale its total jumps from 78 to 183 there. Here the total is Snakemake's too, from a dry run given
``--config planned_ranking=true``, under which the workflow (workflow/rules/common.smk) takes the top seeds in seed
order where the ranking is not there yet: which seeds rank first changes no job count. The dry run counts the jobs
still to run, by rule; the jobs done are those Snakemake's metadata (``.snakemake/metadata/``, one record per
output file, with its rule and its start and end) records for the run's files. The time left sums, over the rules
still to run, their jobs times the mean time this run's finished jobs of that rule took, divided by the
parallelism the run reached so far (the finished jobs' seconds over the span they ran in). A rule none of whose
jobs has finished yet has no time: the ETA is then a lower bound, and says so.

A dry run takes seconds (23 s, 13 CPU-seconds, on a loaded 2-core EPYC at the laptop scale), so
:class:`PipelineWatch` runs one at the first call and again only every :data:`PLAN_EVERY` seconds; between them
the total stays and the jobs done move. The line is shown for a run of a shipped scale in the workflow's own
``results/`` folder (:func:`pipeline_watch`): the dry run needs the scale's name and the workflow's folder.
"""

from __future__ import annotations

import base64
import json
import os
import re
import subprocess
import sys
import time
from collections import Counter
from dataclasses import dataclass, field
from pathlib import Path

import pandas as pd

from .layout import Run

#: Seconds between dry runs of the pipeline: each takes seconds of a core from the jobs it counts, and their
#: total moves only when a job is rerun or a file changed by hand (the checkpoint changes no count).
PLAN_EVERY = 600.0
#: The rule Snakemake runs last to collect every target: no work, no output, never recorded as done.
TARGET_RULE = "all"
#: Where Snakemake keeps one record per output file it made (its persistence layout, record format 6).
METADATA = Path(".snakemake") / "metadata"
_STATS_ROW = re.compile(r"^(\w+)\s+(\d+)$")


def finished_jobs(run: Run, workdir: Path = Path(".")) -> pd.DataFrame:
    """The run's finished jobs by Snakemake's metadata: one row per job (rule, start, end, seconds), of the records
    whose output is under the run's results or figures folder. A record Snakemake marks incomplete, or cannot have
    written whole, is left out; so is one whose output is gone unless it ended after the earliest start of the jobs
    whose outputs are there: a ``temp()`` output Snakemake removed once it was used (the top seeds' group folders)
    is a job done, a file of a run deleted since is not."""
    folder = workdir / METADATA
    roots = tuple(os.path.relpath(Path(root).resolve(), Path(workdir).resolve()) + os.sep
                  for root in (run.results, run.figures))
    jobs: dict[tuple, dict] = {}
    for dirpath, _, files in os.walk(folder):
        for name in files:
            record_path = Path(dirpath, name)
            output = _decoded(record_path.relative_to(folder))
            if output is None or not output.startswith(roots):
                continue
            try:
                record = json.loads(record_path.read_text())
            except (OSError, ValueError):
                continue
            if record.get("incomplete") or record.get("endtime") is None:
                continue
            # a job's outputs share its hash and end; each record's start is stamped as its file was registered
            key = (record.get("rule"), record.get("job_hash"), record["endtime"])
            start = float(record.get("starttime") or record["endtime"])
            job = jobs.setdefault(key, {"rule": record.get("rule"), "start": start, "end": float(record["endtime"]),
                                        "there": False})
            job["start"] = min(job["start"], start)
            job["there"] = job["there"] or (workdir / output).exists()
    table = pd.DataFrame(list(jobs.values()), columns=["rule", "start", "end", "there"])
    first = table.loc[table["there"].astype(bool), "start"].min() if len(table) else float("nan")
    kept = table[table["there"].astype(bool) | (table["end"] >= first)].drop(columns="there")
    return kept.assign(seconds=kept["end"] - kept["start"]).reset_index(drop=True)


def _decoded(relative: Path) -> str | None:
    """The output path a metadata record's file name encodes: urlsafe base64, cut into folders of ``@``-prefixed
    pieces where the name is longer than the file system allows."""
    try:
        return base64.urlsafe_b64decode("".join(part.removeprefix("@") for part in relative.parts)).decode()
    except (ValueError, UnicodeDecodeError):
        return None


def parse_job_stats(text: str) -> Counter:
    """Jobs by rule from a ``snakemake --dry-run --quiet rules`` output's "Job stats" table (its first, where
    Snakemake prints it twice), without the collecting rule :data:`TARGET_RULE`; empty when nothing is to run."""
    counts: Counter = Counter()
    lines = text.splitlines()
    start = next((i for i, line in enumerate(lines) if line.strip() == "Job stats:"), None)
    if start is None:
        return counts
    for line in lines[start + 3:]:  # the title, the header, the dashes
        match = _STATS_ROW.match(line.strip())
        if not match or match[1] == "total":
            break
        if match[1] != TARGET_RULE:
            counts[match[1]] = int(match[2])
    return counts


def jobs_to_run(scale: str, workdir: Path = Path("."), timeout: float = 300) -> Counter:
    """The jobs still to run for the whole run of a shipped ``scale``, by rule: Snakemake's dry run in
    ``workdir`` (the workflow's folder), with the jobs after seed selection counted before it has run. A dry run
    that fails is a ValueError with Snakemake's last line."""
    command = [sys.executable, "-m", "snakemake", "--dry-run", "--quiet", "rules", "--config", f"scale={scale}",
               "planned_ranking=true"]
    result = subprocess.run(command, cwd=workdir, capture_output=True, text=True, timeout=timeout)
    if result.returncode != 0:
        last = (result.stderr.strip().splitlines() or ["(no output)"])[-1]
        raise ValueError(f"the pipeline's dry run failed: {last}")
    return parse_job_stats(result.stdout + result.stderr)


@dataclass(frozen=True)
class Progress:
    """Where the pipeline is: the jobs done, the total, the seconds left (None before any job has a time) and the
    jobs still to run of rules no finished job has timed yet (the seconds left leave them out)."""

    done: int
    total: int
    seconds_left: float | None
    untimed: int

    def line(self) -> str:
        """``pipeline: 57 of 183 jobs done (31%); about 14m left at this run's job times`` (or a lower bound)."""
        from .watch import duration

        share = f" ({100 * self.done / self.total:.0f}%)" if self.total else ""
        head = f"pipeline: {self.done} of {self.total} jobs done{share}"
        if self.done >= self.total:
            return head
        if self.seconds_left is None:
            return f"{head}; time left: not known until a job has finished"
        left = duration(self.seconds_left)
        if self.untimed:
            return f"{head}; at least {left} left ({self.untimed} jobs of rules none of whose jobs has finished yet)"
        return f"{head}; about {left} left at this run's job times"


def progress(finished: pd.DataFrame, planned_left: Counter, finished_then: Counter) -> Progress:
    """The progress from the finished jobs and a dry run's jobs to run (``planned_left``), made when
    ``finished_then`` (jobs by rule) had finished: the jobs finished since come off the dry run's count."""
    now = Counter(finished["rule"])
    left = Counter({rule: max(0, n - (now[rule] - finished_then[rule])) for rule, n in planned_left.items()})
    done = int(len(finished))
    total = done + sum(left.values())
    if finished.empty:
        return Progress(done, total, None, sum(left.values()))
    mean = finished.groupby("rule")["seconds"].mean()
    work = sum(n * mean[rule] for rule, n in left.items() if rule in mean.index)
    untimed = sum(n for rule, n in left.items() if rule not in mean.index)
    span = finished["end"].max() - finished["start"].min()
    parallel = max(1.0, finished["seconds"].sum() / span) if span > 0 else 1.0
    return Progress(done, total, work / parallel, untimed)


def pipeline_watch(run: Run, workdir: Path = Path(".")) -> PipelineWatch | None:
    """The pipeline line's watch of ``run`` when it can have one: a run of a shipped scale (config/scale/) in the
    ``results/`` folder of the workflow in ``workdir``; else None (a run elsewhere, or with overrides, whose
    Snakemake call the watch cannot know)."""
    from .layout import RESULTS_ROOT
    from .watch import is_shipped_scale

    if not (workdir / "Snakefile").is_file() or not is_shipped_scale(run.name):
        return None
    if Path(run.results).resolve() != (workdir / RESULTS_ROOT / run.name).resolve():
        return None
    return PipelineWatch(run, workdir)


@dataclass
class PipelineWatch:
    """The pipeline line of a run of a shipped scale, for a watch that calls :meth:`line` on every refresh: a dry
    run at the first call and every :data:`PLAN_EVERY` seconds, the metadata read at every call."""

    run: Run
    workdir: Path = Path(".")
    every: float = PLAN_EVERY
    _planned: Counter = field(default_factory=Counter)
    _finished_then: Counter = field(default_factory=Counter)
    _planned_at: float = -float("inf")
    _error: str | None = None
    last: Progress | None = None  # the progress of the last call (None after a dry run that failed)

    @property
    def finished(self) -> bool:
        """Whether the last call found every job of the pipeline done."""
        return self.last is not None and self.last.done >= self.last.total

    def line(self, now: float | None = None) -> str:
        """The progress line, or why there is none (a dry run that failed)."""
        now = time.monotonic() if now is None else now
        finished = finished_jobs(self.run, self.workdir)  # once a call: a thousand small files at the laptop scale
        if now - self._planned_at >= self.every:
            try:
                self._planned = jobs_to_run(self.run.name, self.workdir)
                self._error = None
            except (ValueError, subprocess.TimeoutExpired) as exc:
                self._error = str(exc)
            self._finished_then, self._planned_at = Counter(finished["rule"]), now
        if self._error:
            self.last = None
            return f"pipeline: {self._error}"
        self.last = progress(finished, self._planned, self._finished_then)
        return self.last.line()
