"""``efish plan-cluster``: every job of a scale with its expected runtime, memory and cores, for a SLURM profile.

The job list is Snakemake's own (a forced dry run of the workflow at the target
scale, ``snakemake -n --forceall``): each job with its rule, wildcards and
benchmark file. Each job's cost is measured at a smaller scale (the laptop
scale's Snakemake benchmark files, ``results/laptop/benchmarks/**.tsv``) and
scaled by the cost model of its rule:

- ``train``, ``train_policy``: env steps x agents x (3 epochs + 1) x model FLOPs
  per sample (``efish.bench.train.forward_flops``: width^2 terms and the input
  layers); memory by the rollout buffer (arenas x rollout steps x agents x
  (observation + state + 2 widths) values); a later draw of a homing recipe
  (``train/homing_draw_2``, ``scale.homing_seeds``) is its recipe's training;
- assays, seed evaluation and the analyses of an assay: agent-steps (episodes
  x episode steps x agents, summed over the assay's conditions); a top seed's
  own rerun of homing with its draw of the recipes (``top_seed_recipe_assay*``)
  is the run's homing assay again;
- everything else (selection, panels, pages, benchmarks, ...): as measured.

A job's cost is its CPU time (``cpu_time`` of the benchmark file; the wall time
of a job on a shared machine also counts its waiting), and memory above the
smallest resident set of any measured job (the interpreter and its imports)
scales with the memory model. A job of the target without a measured
counterpart (seed 17, say) takes the mean of its rule's measured jobs, each
scaled by its own work. Runtimes assume one core: jobs given more cores (the
training rules) finish sooner if their threads pay. The model is conservative
for training measured at a small width, whose time is not dominated by its
matrix products.
"""

from __future__ import annotations

import dataclasses
import re
import subprocess
from collections.abc import Callable
from pathlib import Path

import pandas as pd
import yaml

from ..config import compose
from ..config.schema import EfishConfig
from ..env.observe import observation_size
from ..layout import BENCHMARKS, parse_recipe_draw
from .train import forward_flops

HEADROOM = 1.5  # the profile's runtime and memory must cover this many times the estimate
COLUMNS = ("rule", "job", "measured", "work_ratio", "runtime_min", "mem_mb", "cores", "profile_runtime_min",
           "profile_mem_mb", "runtime_headroom", "mem_headroom", "ok")
_RULE = re.compile(r"^(?:rule|checkpoint|localrule) (\w+):$")


@dataclasses.dataclass
class Job:
    """One job of the dry run: rule, wildcards, benchmark file (relative to the run's benchmarks folder)."""

    rule: str
    wildcards: dict[str, str]
    benchmark: str | None
    local: bool = False


def parse_dry_run(text: str) -> list[Job]:
    """The jobs of ``snakemake -n`` output (its ``rule X:`` blocks with their wildcards and benchmark)."""
    jobs: list[Job] = []
    for line in text.splitlines():
        if m := _RULE.match(line.strip()):
            jobs.append(Job(m.group(1), {}, None, local=line.strip().startswith("localrule")))
        elif jobs and line.startswith("    wildcards: "):
            pairs = (p.split("=", 1) for p in line.split(": ", 1)[1].split(", "))
            jobs[-1].wildcards = {k: v for k, v in pairs}
        elif jobs and line.startswith("    benchmark: "):
            path = line.split(": ", 1)[1].strip()
            jobs[-1].benchmark = path.split("/benchmarks/", 1)[1] if "/benchmarks/" in path else path
    return [j for j in jobs if not j.local and j.rule != "all"]


def dry_run(overrides: list[str], snakefile: Path = Path("Snakefile")) -> str:
    """Snakemake's forced dry run of the workflow at ``overrides`` (scale=..., other efish overrides)."""
    if not snakefile.is_file():
        raise ValueError(f"no {snakefile} here: run efish plan-cluster in the repository's root, or pass --dry-run "
                         "with a saved `snakemake -n --forceall` output")
    scale = [o.split("=", 1)[1] for o in overrides if o.startswith("scale=")]
    rest = [o for o in overrides if not o.startswith("scale=")]
    config = [f"scale={scale[-1] if scale else 'laptop'}"] + ([f"overrides={' '.join(rest)}"] if rest else [])
    result = subprocess.run(["snakemake", "-n", "--forceall", "--snakefile", str(snakefile), "--config", *config],
                            capture_output=True, text=True, check=False)
    if result.returncode != 0:
        tail = (result.stderr.strip() or result.stdout.strip()).splitlines()[-1:]
        raise ValueError(f"snakemake -n failed: {tail[0] if tail else result.returncode}")
    return result.stdout + result.stderr


def read_benchmarks(folder: Path) -> pd.DataFrame:
    """One row per benchmark file under ``folder``: key (path relative to it), cpu seconds, max RSS (MB)."""
    files = sorted(Path(folder).glob("**/*.tsv"))
    if not files:
        raise ValueError(f"no Snakemake benchmark files under {folder}: run the pipeline at that scale first "
                         "(snakemake --profile workflow/profiles/default), or pass --results")
    rows = []
    for path in files:
        last = pd.read_csv(path, sep="\t").iloc[-1]
        cpu = pd.to_numeric(last.get("cpu_time"), errors="coerce")
        seconds = float(cpu) if pd.notna(cpu) and cpu > 0 else float(last["s"])
        rows.append({"key": str(path.relative_to(folder)), "seconds": seconds,
                     "rss_mb": float(pd.to_numeric(last["max_rss"], errors="coerce"))})
    return pd.DataFrame(rows)


class CostModel:
    """Work (time) and memory units of a job at one scale; ratios of two give the scaling."""

    def __init__(self, overrides: list[str]):
        self.overrides = list(overrides)
        self._cache: dict = {}

    def _cfg(self, *extra: str) -> EfishConfig:
        key = ("cfg", extra)
        if key not in self._cache:
            self._cache[key] = compose([*self.overrides, *extra])
        return self._cache[key]

    def _assay_steps(self, assay: str) -> float:
        """Agent-steps of an assay: episodes x episode steps x agents, summed over its conditions."""
        from ..rollout.assay import condition_configs

        key = ("assay", assay)
        if key not in self._cache:
            configs = condition_configs([*self.overrides, f"assay={assay}"])
            self._cache[key] = float(sum(min(c.assay.episodes, c.scale.max_episodes) * c.env.episode_steps
                                         * c.env.n_agents for c in configs.values()))
        return self._cache[key]

    def _training(self, *extra: str) -> tuple[float, float]:
        cfg = self._cfg(*extra)
        t, n, d = cfg.train, cfg.env.n_agents, observation_size(cfg)
        per_sample = forward_flops(d, t.hidden, 4) + forward_flops(d * n, t.hidden, 1)
        work = t.total_steps * n * (3 * t.epochs + 1) * per_sample
        memory = t.num_envs * t.rollout_steps * n * (d * (1 + n) + 2 * t.hidden)
        return float(work), float(memory)

    def units(self, job: Job) -> tuple[float, float] | None:
        """(work, memory) units of a job, or None for rules whose cost does not scale (taken as measured)."""
        rule, wc = job.rule, job.wildcards
        if rule == "train":
            return self._training()
        if rule == "train_policy":  # a recipe, or a later draw of one: the same training with another seed
            return self._training(f"policy={parse_recipe_draw(wc['policy'])[0]}")
        assay = "selection" if rule == "evaluate_seed" else wc.get("assay")
        if assay and rule == "top_seed_group":  # one job rolls out every top seed that reruns the assay
            steps = self._assay_steps(assay) * self._group_size(assay)
            return steps, steps
        # the top seeds' analyses are the same work as the selected seed's; their top_seed_assay jobs only link
        # the group's tables (taken as measured); a top seed's solo rerun of homing with its draw of the recipes is
        # the run's homing assay again
        if assay and (rule in ("evaluate_seed", "assay", "assay_with_hidden", "top_seed_recipe_assay",
                               "top_seed_recipe_assay_with_hidden")
                      or rule.startswith(("analysis_", "top_seed_analysis_"))):
            steps = self._assay_steps(assay)
            return steps, steps
        return None

    def _group_size(self, assay: str) -> int:
        """The seeds in an assay's top-seed group (efish.run_plan.RunPlan.group_seeds): every top seed for the
        supplement's assays, the others for a claim's assay."""
        scale = self._cfg().scale
        return max(1, scale.top_seeds if assay in scale.top_seed_assays else scale.top_seeds - 1)


def plan_jobs(jobs: list[Job], measured: pd.DataFrame, source: CostModel, target: CostModel) -> pd.DataFrame:
    """Expected CPU minutes and memory of every job of the target from the measured jobs of the source."""
    floor = float(measured["rss_mb"].min())
    by_key = measured.set_index("key")
    twin = {j.benchmark: j for j in jobs if j.benchmark}  # a measured job is the target job of the same benchmark
    rows = []
    for job in jobs:
        units_t = target.units(job)
        if job.benchmark in by_key.index:
            refs = [(by_key.loc[job.benchmark], job)]
        else:  # no measured twin: every measured job of the same rule, each scaled by its own work
            refs = [(by_key.loc[k], twin[k]) for k in by_key.index if k in twin and twin[k].rule == job.rule]
        if not refs:
            rows.append({"rule": job.rule, "job": _label(job), "measured": False})
            continue
        seconds, mem, ratios = [], [], []
        for ref, ref_job in refs:
            units_s = source.units(ref_job)
            time_ratio, mem_ratio = ((units_t[0] / units_s[0], units_t[1] / units_s[1])
                                     if units_t and units_s else (1.0, 1.0))
            seconds.append(ref["seconds"] * time_ratio)
            mem.append(floor + max(0.0, ref["rss_mb"] - floor) * mem_ratio)
            ratios.append(time_ratio)
        rows.append({"rule": job.rule, "job": _label(job), "measured": True, "work_ratio": sum(ratios) / len(ratios),
                     "runtime_min": sum(seconds) / len(seconds) / 60, "mem_mb": sum(mem) / len(mem)})
    return pd.DataFrame(rows)


def _label(job: Job) -> str:
    return ",".join(f"{k}={v}" for k, v in job.wildcards.items() if k != "run") or job.rule


def profile_resources(profile: Path) -> Callable[[str], dict]:
    """rule -> {runtime, mem_mb, cores} of a Snakemake profile (default-resources, set-resources, set-threads)."""
    path = Path(profile) / "config.yaml" if Path(profile).is_dir() else Path(profile)
    if not path.is_file():
        raise ValueError(f"no Snakemake profile at {path}")
    cfg = yaml.safe_load(path.read_text()) or {}
    default, per_rule, threads = (cfg.get("default-resources") or {}, cfg.get("set-resources") or {},
                                  cfg.get("set-threads") or {})

    def resources(rule: str) -> dict:
        r = {**default, **per_rule.get(rule, {})}
        return {"runtime": r.get("runtime"), "mem_mb": r.get("mem_mb"),
                "cores": r.get("cpus_per_task", threads.get(rule, 1))}
    return resources


def check_profile(plan: pd.DataFrame, resources: Callable[[str], dict], headroom: float = HEADROOM) -> pd.DataFrame:
    """The plan with the profile's runtime, memory and cores per job, the headroom they leave, and ``ok`` where
    both cover ``headroom`` times the estimate (unmeasured jobs: ok when the profile sets a value at all)."""
    out = plan.copy()
    res = out["rule"].map(resources)
    out["cores"] = [r["cores"] for r in res]
    out["profile_runtime_min"] = [r["runtime"] for r in res]
    out["profile_mem_mb"] = [r["mem_mb"] for r in res]
    for col in ("runtime_min", "mem_mb", "work_ratio"):
        if col not in out:
            out[col] = float("nan")
    out["runtime_headroom"] = pd.to_numeric(out["profile_runtime_min"]) / out["runtime_min"]
    out["mem_headroom"] = pd.to_numeric(out["profile_mem_mb"]) / out["mem_mb"]
    measured = out["measured"].astype(bool)
    out["ok"] = ~measured | ((out["runtime_headroom"] >= headroom) & (out["mem_headroom"] >= headroom))
    return out[list(COLUMNS)]


def suggested_resources(checked: pd.DataFrame, headroom: float = HEADROOM) -> dict[str, dict[str, int]]:
    """Per rule: runtime (min, rounded up to 10) and mem_mb (rounded up to 500) covering ``headroom`` x its
    largest estimate: what the profile's set-resources should hold."""
    out = {}
    for rule, g in checked[checked["measured"].astype(bool)].groupby("rule"):
        runtime = headroom * g["runtime_min"].max()
        mem = headroom * g["mem_mb"].max()
        out[rule] = {"runtime": int(-(-runtime // 10) * 10), "mem_mb": int(-(-mem // 500) * 500)}
    return out


def format_plan(checked: pd.DataFrame, headroom: float = HEADROOM) -> str:
    """The plan as a table, then a summary: total CPU hours, and which rules lack headroom."""
    shown = checked.assign(measured=checked["measured"].map({True: "yes", False: "no"}))
    text = shown.to_string(index=False, float_format=lambda v: f"{v:,.1f}", na_rep="-")
    measured = checked[checked["measured"].astype(bool)]
    lines = [text, (f"{len(checked)} jobs, {len(measured)} with a measured counterpart; "
                    f"{measured['runtime_min'].sum() / 60:,.1f} CPU hours in all")]
    short = sorted(set(checked.loc[~checked["ok"], "rule"]))
    lines.append(f"the profile leaves {headroom}x headroom for every measured job" if not short else
                 f"the profile leaves less than {headroom}x headroom for: {', '.join(short)}")
    return "\n".join(lines)


def plan_cluster(overrides: list[str], source_scale: str, results: Path, profile: Path,
                 dry_run_text: str | None = None) -> pd.DataFrame:
    """Every job of the workflow at ``overrides`` (its dry run, or ``dry_run_text``), estimated from the benchmark
    files of the ``source_scale`` run in ``results`` and checked against ``profile``."""
    measured = read_benchmarks(Path(results) / BENCHMARKS)
    jobs = parse_dry_run(dry_run_text if dry_run_text is not None else dry_run(overrides))
    if not jobs:
        raise ValueError("the dry run lists no jobs")
    plan = plan_jobs(jobs, measured, CostModel([f"scale={source_scale}"]), CostModel(overrides))
    return check_profile(plan, profile_resources(profile))
