# Shared settings: the scale and its efish config, read once. Every number the
# rules need (seeds, assays, panels) comes from efish's config; none is repeated here.
import functools
import hashlib
import json
import re
import shlex
import sys
from pathlib import Path

from efish.analysis.claim_parts import analysis_table
from efish.analysis.claims import claim_tables, produced_tables
from efish.analysis.registry import ANALYSES, analyses_for, tables_written
from efish._numba_cache import source_digest
from efish.config import ConfigError, compose, config_dir, run_name
from efish.env.observe import observation_size
from efish.rollout.assay import check_observation_sizes, condition_configs, policies_needed
from efish.figures.registry import PANELS, drawable
from efish.figures.render import input_paths

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
    digest = hashlib.sha256(repr((SCALE, OVERRIDES, ASSAYS, source_digest())).encode())
    for path in sorted(config_dir().rglob("*.yaml")):
        digest.update(path.read_bytes())
    cache = Path(".snakemake/efish") / f"assays-{digest.hexdigest()[:16]}.json"
    if cache.is_file():
        return json.loads(cache.read_text())
    checked = {name: assay_policies(name) for name in ASSAYS}
    cache.parent.mkdir(parents=True, exist_ok=True)
    cache.write_text(json.dumps(checked))
    return checked


ASSAY_POLICIES = checked_assays()
HIDDEN_ASSAYS = [name for name in ASSAYS if assay_config(name).assay.record_hidden]
# The analyses of each assay of the scale whose tables it writes (dynamics waits for assay.record_hidden).
ASSAY_ANALYSES = {name: analyses_for(name, tables_written(assay_config(name).assay)) for name in ASSAYS}
DRAWABLE = drawable(CFG.scale)


def claims_read(names):
    """The tables the claims read among those assays ``names`` write, as paths under ``results/{run}/``."""
    produced = produced_tables({name: assay_config(name).assay for name in names})
    return [path for path in claim_tables() if path in produced]


# Verdicts across seeds. Each top seed other than the selected one reruns every claim's assay,
# i.e. every assay of the scale that some claim reads and whose conditions act (at least in part) with the selected
# policy, into results/{run}/seeds/seed_{n}/ with the layout of results/{run}/, and only the analyses the claims
# read. An assay acted only by recipe policies (homing) gives the same tables for every seed: not rerun; its claims
# are "not run" for the other seeds.
SEED_CLAIM_ASSAYS = [name for name in ASSAYS if "selected" in ASSAY_POLICIES[name] and claims_read([name])]
SEED_CLAIM_TABLES = claims_read(SEED_CLAIM_ASSAYS)
# Every assay a top seed may run under results/{run}/seeds/seed_{n}/assays/: the claims' and the supplement's.
TOP_SEED_ASSAYS = sorted({*SEED_CLAIM_ASSAYS, *CFG.scale.top_seed_assays})
TOP_SEED_HIDDEN = [name for name in TOP_SEED_ASSAYS if assay_config(name).assay.record_hidden]


wildcard_constraints:
    run=re.escape(RUN),
    seed=r"\d+",
    assay=r"[A-Za-z0-9_\-]+",


def folder_of(name, up=0):
    """A params function: the folder of output ``name`` (a name or an index), or the folder ``up`` levels
    above it. It is what efish's ``--out`` takes, so no rule repeats an output path."""
    return lambda wildcards, output: str(Path(output[name]).parents[up])


def seed_folder(seed=None):
    """Where a top seed other than the selected one keeps the layout of results/{run}/: '' for the run's own
    (the selected seed's) outputs, 'seeds/seed_<seed>/' for another seed's (``seed`` may be '{seed}')."""
    return "" if seed is None else f"seeds/seed_{seed}/"


def analysis_inputs(analysis, seed=None):
    """The rollout tables an analysis reads, by name, for the {assay} wildcard (of top seed ``seed``)."""
    return {t: f"results/{{run}}/{seed_folder(seed)}assays/{{assay}}/{t}.parquet" for t in analysis.reads}


def analysis_outputs(analysis, run="{run}", assay="{assay}", seed=None):
    """The tables an analysis writes, by name: results/{run}/analysis/<analysis>/{assay}/<table>.parquet, or
    results/{run}/seeds/seed_<seed>/analysis/... for another top seed."""
    return {t: f"results/{run}/{seed_folder(seed)}analysis/{analysis.name}/{assay}/{t}.parquet"
            for t in analysis.outputs}


def seed_analysis_assays(analysis):
    """The assays the other top seeds rerun whose ``analysis`` tables some claim reads (only those analyses run)."""
    return [a for a in SEED_CLAIM_ASSAYS if any(analysis_table(analysis.name, a, t) in SEED_CLAIM_TABLES
                                                for t in analysis.outputs)]


def panel_inputs(panel):
    """Every table a panel reads, at this scale (the same expansion efish figure uses)."""
    return [str(path) for paths in input_paths(panel, Path(f"results/{RUN}"), len(SEEDS)).values() for path in paths]


def selected_policy(wildcards):
    """The final checkpoint of the seed the select_seed checkpoint chose."""
    chosen = checkpoints.select_seed.get(run=wildcards.run).output.seed
    seed = int(Path(chosen).read_text().strip())
    return f"results/{wildcards.run}/train/seed_{seed}/final.pt"


def assay_policies_input(wildcards):
    """The final checkpoint of every policy an assay's conditions act with, by policy name. The ``selected`` policy
    is the seed the select_seed checkpoint chose, or seed {seed} for a top seed's run (results/{run}/seeds/)."""
    seed = getattr(wildcards, "seed", None)

    def path(name):
        if name != "selected":
            return f"results/{wildcards.run}/train/{name}/final.pt"
        return selected_policy(wildcards) if seed is None else f"results/{wildcards.run}/train/seed_{seed}/final.pt"

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
    assay under results/{run}/seeds/seed_{n}/ for its own claims table."""
    return top_seeds(wildcards)[1:]


def other_seed_claims(wildcards):
    """The claims tables of the other top seeds, in ranking order (the claims rule combines them)."""
    return [f"results/{wildcards.run}/seeds/seed_{seed}/claims/claims.parquet" for seed in other_top_seeds(wildcards)]


def seed_claims_args(wildcards, input):
    """efish claims's --ranking and --seed-claims SEED=PATH of the other top seeds (none: the selected seed alone)."""
    pairs = [f"{seed}={path}" for seed, path in zip(other_top_seeds(wildcards), other_seed_claims(wildcards))]
    return " ".join([f"--ranking {input.ranking} --seed-claims", *pairs])


def top_seed_tables(wildcards):
    """The episodes tables of the top seeds in assay {assay} (supplement): results/{run}/seeds/seed_{n}/assays/."""
    return [f"results/{wildcards.run}/seeds/seed_{seed}/assays/{wildcards.assay}/episodes.parquet"
            for seed in top_seeds(wildcards)]


def panel_of(wildcards):
    """The registered panel named by the wildcards; an unknown one is one clear error."""
    key = f"{wildcards.figure}/{wildcards.panel}"
    if key not in PANELS:
        fail(f"unknown panel {key!r}: choose one of {', '.join(PANELS)}")
    return PANELS[key]


# The assays whose clips the report shows (issue 15): homing, foraging in the patchy and the wide arena, the
# resident and the intruder at one patch.
CLIP_ASSAYS = [name for name in ("homing", "patchy4", "wide2", "onepatch") if name in ASSAYS]


def clip_condition(wildcards):
    """The clip's condition: the first of the assay's config (config/assay/<name>.yaml)."""
    return next(iter(assay_config(wildcards.assay).assay.conditions))


def render_targets():
    """The clips and the contact sheet of this run (for rule all)."""
    return [f"figures/{RUN}/clips/{name}.gif" for name in CLIP_ASSAYS] + [f"figures/{RUN}/contact_sheet.png"]


def claims_inputs(wildcards):
    """The claims' tables among those the assays of this scale write (rollout tables and their analyses); for a top
    seed's claims (wildcard {seed}) those its rerun assays write under results/{run}/seeds/seed_{seed}/."""
    seed = getattr(wildcards, "seed", None)
    paths = claims_read(ASSAYS) if seed is None else SEED_CLAIM_TABLES
    return [f"results/{wildcards.run}/{seed_folder(seed)}{path}" for path in paths]


def all_targets():
    """Every final output of the pipeline for this run."""
    targets = [
        f"results/{RUN}/bench/bench_physics.json",
        f"results/{RUN}/bench/bench_accuracy.parquet",
        f"figures/{RUN}/bench/bench_accuracy.png",
        f"figures/{RUN}/bench/bench_accuracy.pdf",
        f"results/{RUN}/bench/bench_scaling.parquet",
        f"results/{RUN}/bench/bench_scaling.png",
        f"results/{RUN}/bench/bench_scaling.pdf",
    ]
    targets += [f"results/{RUN}/assays/{a}/{t}.parquet" for a in ASSAYS for t in ("steps", "episodes", "food")]
    targets += [f"results/{RUN}/assays/{a}/hidden.parquet" for a in HIDDEN_ASSAYS]
    if CFG.scale.top_seeds:
        targets += [f"results/{RUN}/seeds/{assay}/episodes.parquet" for assay in CFG.scale.top_seed_assays]
    targets += [path for a, analyses in ASSAY_ANALYSES.items() for an in analyses
                for path in analysis_outputs(an, RUN, a).values()]
    targets += [f"figures/{RUN}/{p.figure}/{p.name}.{ext}" for p in DRAWABLE for ext in ("png", "pdf")]
    pages = {p.figure for p in DRAWABLE}
    targets += [f"figures/{RUN}/{fig}.{ext}" for fig in sorted(pages) for ext in ("png", "pdf")]
    targets += render_targets()
    targets += [f"results/{RUN}/claims/claims.parquet", f"results/{RUN}/claims/claims.md"]
    return targets
