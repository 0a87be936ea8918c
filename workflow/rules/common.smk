# Shared settings: the scale and its efish config, read once. Every number the
# rules need (seeds, assays, panels) comes from efish's config; none is repeated here.
import functools
import hashlib
import json
import re
import shlex
import sys
from pathlib import Path

from efish.claims import claim_tables, produced_tables
from efish.analysis.registry import ANALYSES, analyses_for, tables_written
from efish._numba_cache import source_digest
from efish.config import ConfigError, compose, config_dir, run_name
from efish.env.observe import observation_size
from efish.rollout.assay import check_observation_sizes, condition_configs, policies_needed
from efish.figures.registry import PANELS, drawable
from efish.figures.render import input_paths
from efish.layout import (
    CLAIM_PARTS,
    CLAIMS_BY_STAGE,
    CLAIMS_BY_STAGE_FIGURE,
    CLAIMS_PAGE,
    CLAIMS_TABLE,
    CLAIMS_TRENDS,
    CLAIMS_TRENDS_PAGE,
    FIGURE_FORMATS,
    ROLLOUT_TABLES,
    RANKING,
    SELECTED_SEED,
    Run,
    analysis_table,
    assay_table,
    bench_file,
    scene_table,
    seed_name,
    selection_table,
    stacked_seeds_table,
    stage_copy,
    stage_name,
    stage_file,
    top_seed_copy,
    training_file,
)

CONFIG_KEYS = ("scale", "overrides", "run")


def fail(message):
    """Stop the workflow with one line on stderr (no traceback), before any job runs."""
    sys.stderr.write(f"efish workflow: {message}\n")
    sys.exit(1)


if unknown := sorted(set(config) - set(CONFIG_KEYS)):
    fail(f"unknown --config key(s) {', '.join(unknown)}: the allowed keys are {', '.join(CONFIG_KEYS)}")
SCALE = str(config.get("scale", "laptop"))
# Extra Hydra overrides for every efish call, e.g. --config overrides="physics.tolerance=1e-6"
OVERRIDES = shlex.split(str(config.get("overrides", "")))
# The run's folders: results/{RUN}/ and figures/{RUN}/. The scale as shipped, else the scale and a hash of the
# overrides, or --config run=NAME; two configs never share a folder.
RUN = str(config.get("run") or run_name(SCALE, OVERRIDES))
if not re.fullmatch(r"[A-Za-z0-9_.\-]+", RUN):
    fail(f"run={RUN!r} is not a folder name: use letters, digits, '_', '.' and '-'")


@functools.lru_cache(maxsize=None)
def efish_config(*overrides):
    """The validated efish config at this scale with the user's overrides (composed once per override set);
    bad input stops the workflow before any job runs, with efish's one-line message."""
    try:
        return compose([f"scale={SCALE}", *OVERRIDES, *overrides])
    except ConfigError as exc:
        fail(f"efish config: {exc}")


CFG = efish_config()
SEEDS = list(range(1, CFG.scale.seeds + 1))
ARGS = " ".join(shlex.quote(o) for o in [f"scale={SCALE}", *OVERRIDES])  # passed on to every efish call


def assay_config(name):
    """The composed config of assay ``name`` (config/assay/<name>.yaml); an unknown name is one clear error."""
    return efish_config(f"assay={name}")


ASSAYS = [assay_config(name).assay.name for name in CFG.scale.assays]
# Every other assay file in config/assay/: not in the default target, but its tables are built when asked for
# (snakemake results/<run>/assays/<name>/steps.parquet), so a new question is one YAML file. Checked like the
# scale's assays: a file that does not compose stops every run, in one line naming it.
ASKED_ASSAYS = sorted(p.stem for p in (config_dir() / "assay").glob("*.yaml") if p.stem not in ASSAYS)
POLICY_RECIPES = sorted(p.stem for p in (config_dir() / "policy").glob("*.yaml"))


def assay_policies(name):
    """Policy name -> conditions of assay ``name``; every condition composes, its policy exists and its observation
    fits that policy: checked here, so bad input stops before any job with one line naming it."""
    try:
        configs = condition_configs([f"scale={SCALE}", *OVERRIDES, f"assay={name}"])
        needed = policies_needed(configs)
        unknown = sorted(set(needed) - {"selected", *POLICY_RECIPES})
        if unknown:
            raise ValueError(f"assay {name} asks for policies {', '.join(unknown)}: choose selected or one of "
                             f"{', '.join(POLICY_RECIPES)} (files in config/policy/)")
        sizes = {p: observation_size(efish_config(*([] if p == "selected" else [f"policy={p}"]))) for p in needed}
        check_observation_sizes(configs, sizes)
    except (ConfigError, ValueError) as exc:
        fail(str(exc))
    return needed


def checked_assays():
    """``assay_policies`` of every assay, cached in .snakemake/efish/ under a hash of the config tree, the efish
    sources, the scale and the overrides: composing every condition costs seconds, and each Snakemake call
    (each cluster job too) reads this file again."""
    digest = hashlib.sha256(repr((SCALE, OVERRIDES, ASSAYS, ASKED_ASSAYS, source_digest())).encode())
    for path in sorted(config_dir().rglob("*.yaml")):
        digest.update(path.read_bytes())
    cache = Path(".snakemake/efish") / f"assays-{digest.hexdigest()[:16]}.json"
    if cache.is_file():
        return json.loads(cache.read_text())
    checked = {name: assay_policies(name) for name in [*ASSAYS, *ASKED_ASSAYS]}
    cache.parent.mkdir(parents=True, exist_ok=True)
    cache.write_text(json.dumps(checked))
    return checked


ASSAY_POLICIES = checked_assays()
HIDDEN_ASSAYS = [name for name in ASSAYS if assay_config(name).assay.record_hidden]
# What the assay rules may build, split by whether the assay records hidden states (assay_with_hidden).
BUILDABLE_ASSAYS = {hidden: [name for name in [*ASSAYS, *ASKED_ASSAYS]
                             if assay_config(name).assay.record_hidden == hidden] for hidden in (False, True)}
# The analyses of each assay of the scale whose tables it writes (dynamics waits for assay.record_hidden).
ASSAY_ANALYSES = {name: analyses_for(name, tables_written(assay_config(name).assay)) for name in ASSAYS}
DRAWABLE = drawable(CFG.scale)


def claims_read(names):
    """The tables the claims read among those assays ``names`` write, as paths relative to a run's results."""
    produced = produced_tables({name: assay_config(name).assay for name in names})
    return [path for path in claim_tables() if path in produced]


# Verdicts across seeds. Each top seed other than the selected one reruns every claim's assay,
# i.e. every assay of the scale that some claim reads and whose conditions act (at least in part) with the selected
# policy, into results/{run}/seeds/seed_{n}/ with the layout of results/{run}/, and only the analyses the claims
# read. An assay acted only by recipe policies (homing) gives the same tables for every seed: not rerun; its claims
# are "not run" for the other seeds.
SEED_CLAIM_ASSAYS = [name for name in ASSAYS if "selected" in ASSAY_POLICIES[name] and claims_read([name])]
SEED_CLAIM_TABLES = claims_read(SEED_CLAIM_ASSAYS)
# Every assay a top seed may run (in its copy of the layout): the claims' and the supplement's.
TOP_SEED_ASSAYS = sorted({*SEED_CLAIM_ASSAYS, *CFG.scale.top_seed_assays})
TOP_SEED_HIDDEN = [name for name in TOP_SEED_ASSAYS if assay_config(name).assay.record_hidden]


CLIP_ASSAYS = [name for name in CFG.scale.clip_assays if name in ASSAYS]


# Claims along training (learning.smk). Every seed keeps its policy at the fractions scale.keep_stages of its
# training (stage_<k>.pt, k = 1..K); at each kept stage the selected seed's policy reruns every claim's assay
# (SEED_CLAIM_ASSAYS, at most scale.stage_episodes episodes per condition) in results/{run}/learning/stage_<k>/, with
# the analyses and the claims. A last stage at fraction 1 is the final policy: the run's own claims stand for it.
KEPT_STAGES = list(range(1, len(CFG.train.keep_stages) + 1))
LAST_STAGE_IS_FINAL = bool(KEPT_STAGES) and CFG.train.keep_stages[-1] == 1.0
STAGES = KEPT_STAGES[:-1] if LAST_STAGE_IS_FINAL else KEPT_STAGES  # the stages with their own copy of the layout
STAGE_ARGS = " ".join([ARGS, shlex.quote(f"scale.max_episodes={CFG.scale.stage_episodes}")])


wildcard_constraints:
    run=re.escape(RUN),
    seed=r"\d+",
    stage=r"\d+",
    assay=r"[A-Za-z0-9_\-]+",


# ------------------------------------------------------------------ paths: every one from efish.layout
RULE_RUN = Run("{run}")  # the rules' patterns ({run} and the rule's other wildcards)
THIS_RUN = Run(RUN)  # this run's own files (rule all, panel inputs)


# The copies of the layout inside a run (efish.layout.Run.within): a top seed's and a training stage's.
TOP_SEED = top_seed_copy("{seed}")
STAGE = stage_copy("{stage}")


def copy_of(wildcards):
    """The copy of the layout a job of a top seed ({seed}) or a training stage ({stage}) works in; None: the run."""
    seed, stage = getattr(wildcards, "seed", None), getattr(wildcards, "stage", None)
    return top_seed_copy(seed) if seed is not None else stage_copy(stage) if stage is not None else None


def results(relative, copy=None, run=RULE_RUN):
    """A file under the run's results folder (or under the copy of the layout ``copy``: TOP_SEED, STAGE) from a
    relative name of efish.layout, e.g. ``results(assay_table("{assay}", "steps"))``."""
    return str(run.within(copy).path(relative))


def log(job, copy=None):
    """The job's log file, results/{run}/logs/<job>.log (a copy's under logs/<copy>/)."""
    return str(RULE_RUN.within(copy).log(job))


def benchmark(job, copy=None):
    """The job's Snakemake timing file, results/{run}/benchmarks/<job>.tsv (read by efish bench pipeline)."""
    return str(RULE_RUN.within(copy).benchmark(job))


def efish(command, arguments=""):
    """The shell line of an efish call: the (sub)command, the run's overrides (params.overrides) right after it,
    the rule's own arguments, and the output into the job's log. Every rule runs efish this way, so none repeats
    the redirection or the overrides (which come before options such as --seed-claims that take many values)."""
    return f"efish {command} {{params.overrides}} {arguments} > {{log}} 2>&1"


def folder_of(name, up=0):
    """A params function: the folder of output ``name`` (a name or an index), or the folder ``up`` levels
    above it. It is what efish's ``--out`` takes, so no rule repeats an output path."""
    return lambda wildcards, output: str(Path(output[name]).parents[up])


def assay_outputs(hidden, copy=None):
    """The tables an assay job writes, by name (hidden: the assay records the GRU state), in the copy of the
    layout ``copy`` if given."""
    names = [*ROLLOUT_TABLES, *(["hidden"] if hidden else [])]
    return {t: results(assay_table("{assay}", t), copy) for t in names}


def analysis_inputs(analysis, copy=None):
    """The rollout tables an analysis reads, by name, for the {assay} wildcard (in the copy ``copy``)."""
    return {t: results(assay_table("{assay}", t), copy) for t in analysis.reads}


def analysis_outputs(analysis, run=RULE_RUN, assay="{assay}", copy=None):
    """The tables an analysis writes, by name (under the copy of the layout ``copy`` if given)."""
    return {t: results(analysis_table(analysis.name, assay, t), copy, run) for t in analysis.outputs}


def seed_analysis_assays(analysis):
    """The assays the other top seeds rerun whose ``analysis`` tables some claim reads (only those analyses run)."""
    return [a for a in SEED_CLAIM_ASSAYS if any(analysis_table(analysis.name, a, t) in SEED_CLAIM_TABLES
                                                for t in analysis.outputs)]


def panel_inputs(panel):
    """Every table a panel reads, at this scale (the same expansion efish figure uses)."""
    return [str(path) for paths in input_paths(panel, THIS_RUN.results, len(SEEDS)).values() for path in paths]


def seed_policy(wildcards, seed):
    return results(training_file(seed_name(seed), "final.pt"), run=Run(wildcards.run))


def stage_policy(run, seed, k):
    """Seed ``seed``'s policy at its k-th kept training stage (train.keep_stages)."""
    return results(training_file(seed_name(seed), stage_file(k)), run=Run(run))


def selected_seed(wildcards):
    """The seed the select_seed checkpoint chose."""
    return int(Path(checkpoints.select_seed.get(run=wildcards.run).output.seed).read_text().strip())


def assay_policies_input(wildcards):
    """The final checkpoint of every policy an assay's conditions act with, by policy name. The ``selected`` policy
    is the seed the select_seed checkpoint chose (at training stage {stage} for a stage's assays), or seed {seed}
    for a top seed's rerun."""
    seed, stage = getattr(wildcards, "seed", None), getattr(wildcards, "stage", None)

    def path(name):
        if name != "selected":
            return results(training_file(name, "final.pt"), run=Run(wildcards.run))
        if stage is not None:
            return stage_policy(wildcards.run, selected_seed(wildcards), stage)
        return seed_policy(wildcards, selected_seed(wildcards) if seed is None else seed)

    return {name: path(name) for name in ASSAY_POLICIES.get(wildcards.assay, ["selected"])}


def policy_args(wildcards, input):
    """efish assay's --policy entries: NAME=PATH for every input policy."""
    return " ".join(f"{name}={path}" for name, path in input.items())


def top_seeds(wildcards):
    """The ``scale.top_seeds`` best-ranked seeds, from the select_seed checkpoint's ranking table."""
    import pandas as pd

    ranking = pd.read_parquet(checkpoints.select_seed.get(run=wildcards.run).output.ranking)
    return [int(s) for s in ranking["seed"].head(CFG.scale.top_seeds)]


def other_top_seeds(wildcards):
    """The top seeds other than the selected one (the ranking's first row), best first: each reruns every claim's
    assay in its own copy of the layout for its own claims table."""
    return top_seeds(wildcards)[1:]


def other_seed_claims(wildcards):
    """The claims tables of the other top seeds, in ranking order (the claims rule combines them)."""
    return [results(CLAIMS_TABLE, top_seed_copy(seed), Run(wildcards.run)) for seed in other_top_seeds(wildcards)]


def seed_claims_args(wildcards, input):
    """efish claims's --ranking and --seed-claims SEED=PATH of the other top seeds (none: the selected seed alone)."""
    pairs = [f"{seed}={path}" for seed, path in zip(other_top_seeds(wildcards), other_seed_claims(wildcards),
                                                    strict=True)]
    return " ".join([f"--ranking {input.ranking} --seed-claims", *pairs])


def top_seed_tables(wildcards):
    """The episodes tables of the top seeds in assay {assay} (stacked for the supplement)."""
    return [results(assay_table(wildcards.assay, "episodes"), top_seed_copy(seed), Run(wildcards.run))
            for seed in top_seeds(wildcards)]


def claims_inputs(wildcards):
    """The claims' tables among those the assays of this scale write (rollout tables and their analyses); for a top
    seed's claims (wildcard {seed}) or a training stage's ({stage}) those its rerun assays write in its copy of the
    layout."""
    copy = copy_of(wildcards)
    paths = claims_read(ASSAYS) if copy is None else SEED_CLAIM_TABLES
    return [results(path, copy, Run(wildcards.run)) for path in paths]


# ------------------------------------------------------------------ learning
def stage_parts(run=RULE_RUN):
    """Each kept stage's claim_parts.parquet in stage order: its copy's, or the run's own for a last stage at
    fraction 1 (the final policy)."""
    own = [results(CLAIM_PARTS, run=run)] if LAST_STAGE_IS_FINAL else []
    return [results(CLAIM_PARTS, stage_copy(k), run) for k in STAGES] + own


def stage_policies(wildcards):
    """The selected seed's stage files, k = 1..K (their records hold the env steps trained)."""
    return [stage_policy(wildcards.run, selected_seed(wildcards), k) for k in KEPT_STAGES]


def stage_episodes():
    """The cap on the episodes per assay condition at each kept stage (the last, at fraction 1, is the run's)."""
    return [CFG.scale.stage_episodes] * len(STAGES) + [CFG.scale.max_episodes] * LAST_STAGE_IS_FINAL


def learning_target(wildcards):
    """The learning target's inputs; without stages one line and no job (it would otherwise train and assay for
    nothing before failing)."""
    if not KEPT_STAGES:
        fail("the learning target needs scale.keep_stages, e.g. --config overrides=\"scale.keep_stages=[0.5,1.0]\"")
    return list(learning_outputs(THIS_RUN).values())


def keyed(values):
    """``1=a 2=b ...``: efish claims-by-stage's K=VALUE arguments, one per kept stage in order (a string, the
    placeholder of an input behind a checkpoint not yet run, is passed through)."""
    if isinstance(values, str):
        return values
    return " ".join(f"{k}={v}" for k, v in zip(KEPT_STAGES, values, strict=True))


def learning_outputs(run=RULE_RUN, reported=False):
    """What claims-by-stage writes: the stacked parts, the trends, the claims page with its trend lines, and the
    figure (PNG, PDF); ``reported``: the figure's PNG goes into the report, beside the claims."""
    tables = {"table": CLAIMS_BY_STAGE, "trends": CLAIMS_TRENDS, "page": CLAIMS_TRENDS_PAGE}
    figure = {ext: str(run.figures / f"{CLAIMS_BY_STAGE_FIGURE}.{ext}") for ext in FIGURE_FORMATS}
    if reported:
        figure["png"] = report(figure["png"], caption="../report/learning.rst", category="Claims")
    return {name: results(path, run=run) for name, path in tables.items()} | figure


# ------------------------------------------------------------------ figures
# One job per figure draws each of its panels (PNG, PDF) and its page from the same tables.
FIGURE_PANELS = {}
for _panel in DRAWABLE:
    FIGURE_PANELS.setdefault(_panel.figure, []).append(_panel)


def figure_outputs(figure, run=RULE_RUN):
    """Every file a figure's job writes: each panel's PNG and PDF, then the page's."""
    panels = [run.panel(figure, p.name, ext) for p in FIGURE_PANELS[figure] for ext in FIGURE_FORMATS]
    return [str(path) for path in panels + [run.page(figure, ext) for ext in FIGURE_FORMATS]]


def figure_legend(figure):
    """(panel, caption, tables) of every panel of ``figure`` drawn at this scale, for the report's captions (reST:
    the caption escaped, the tables as literals)."""
    return [(p.name, p.report_caption, ", ".join(f"``{path}``" for path in p.inputs.values()) or "none (a schematic)")
            for p in FIGURE_PANELS[figure]]


def report_entry(figure, path):
    """A figure job's output as the report shows it: each panel's PNG under its figure's category with the
    figure's legend, the page's PNG under "Figure pages"; PDFs are not in the report."""
    if not path.endswith(".png"):
        return path
    if Path(path).parent.name == figure:
        return report(path, caption="../report/panel.rst", category=figure, labels={"panel": Path(path).stem})
    return report(path, caption="../report/figure_page.rst", category="Figure pages", labels={"figure": figure})


def render_targets():
    """The clips and the contact sheet of this run (for rule all)."""
    return [str(THIS_RUN.clip(name)) for name in CLIP_ASSAYS] + [str(THIS_RUN.contact_sheet)]


def all_targets():
    """Every final output of the pipeline for this run."""
    targets = [results(bench_file(name), run=THIS_RUN) for name in
               ("bench_physics.json", "bench_accuracy.parquet", "bench_scaling.parquet")]
    targets += [str(THIS_RUN.bench_figure(name, ext)) for name in ("bench_accuracy", "bench_scaling")
                for ext in FIGURE_FORMATS]
    targets += [results(assay_table(a, t), run=THIS_RUN) for a in ASSAYS for t in ROLLOUT_TABLES]
    targets += [results(assay_table(a, "hidden"), run=THIS_RUN) for a in HIDDEN_ASSAYS]
    if CFG.scale.top_seeds:
        targets += [results(stacked_seeds_table(assay), run=THIS_RUN) for assay in CFG.scale.top_seed_assays]
    targets += [path for a, analyses in ASSAY_ANALYSES.items() for an in analyses
                for path in analysis_outputs(an, THIS_RUN, a).values()]
    targets += [path for figure in FIGURE_PANELS for path in figure_outputs(figure, THIS_RUN)]
    targets += render_targets()
    targets += [results(name, run=THIS_RUN) for name in (CLAIMS_TABLE, CLAIM_PARTS, CLAIMS_PAGE)]
    if CFG.scale.learning:
        targets += list(learning_outputs(THIS_RUN).values())
    return targets
