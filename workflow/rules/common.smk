# Shared glue: the runs' plans, read once, and the helpers the rules use to name their files. What the workflow
# builds (the scale's assays and policies, the top seeds' and the stages' reruns, the panels by figure, the
# targets) is planned by efish.run_plan, which the tests reach; every number comes from efish's config. A sweep
# (--config sweep=..., efish.sweep) is one plan per point, each a run folder of its own: a rule asks the plan of
# its job's {run} (plan_of), and a wildcard constraint allows what any plan builds.
import re
import sys
from pathlib import Path

from efish import run_plan, sweep
from efish.analysis.registry import ANALYSES
from efish.figures.registry import PANELS
from efish.layout import (
    CLAIM_PARTS,
    CLAIMS_PAGE,
    CLAIMS_TABLE,
    ROLLOUT_TABLES,
    RANKING,
    RECIPE_PARTS,
    SELECTED_SEED,
    Run,
    assay_table,
    bench_file,
    scene_table,
    seed_name,
    selection_table,
    stacked_seeds_table,
    stage_copy,
    stage_name,
    stage_file,
    recipe_draw,
    top_seed_copy,
    top_seed_group,
    training_file,
)


def fail(message):
    """Stop the workflow with one line on stderr (no traceback), before any job runs."""
    sys.stderr.write(f"efish workflow: {message}\n")
    sys.exit(1)


# `efish watch`'s pipeline line counts the jobs of a whole run before the select_seed checkpoint has run, with a
# dry run given --config planned_ranking=true: where the checkpoint's ranking is not there yet, the top seeds are
# taken in seed order (their number, not which they are, is what the count needs). Only a dry run may plan so.
PLANNED_RANKING = str(config.pop("planned_ranking", "false")).lower() in ("true", "1", "yes")


# Bad input (a --config key, a run name, a config, an assay file, a sweep) stops here, in one line. Checking every
# assay's conditions costs seconds, so each plan keeps its answer in .snakemake/efish/ for the next parse.
try:
    PLANS = {plan.run: plan for plan in sweep.run_plans(config)}
except run_plan.PlanError as exc:
    fail(str(exc))


def plan_of(wildcards):
    """The plan of the job's run ({run})."""
    return PLANS[wildcards.run]


def of_plan(get):
    """A params or input function: ``get`` of the job's plan, e.g. ``of_plan(lambda plan: plan.args)``."""
    return lambda wildcards: get(plan_of(wildcards))


def across(get):
    """What any plan has: the items of ``get(plan)`` over every plan, each once, in the plans' order."""
    return list(dict.fromkeys(item for plan in PLANS.values() for item in get(plan)))


def by_plan(get):
    """The plans grouped by ``get(plan)``: (value, runs) pairs, for a rule whose outputs differ between points."""
    groups = {}
    for plan in PLANS.values():
        groups.setdefault(get(plan), []).append(plan.run)
    return list(groups.items())


def any_of(names):
    """A wildcard constraint matching exactly ``names`` (none: a pattern no wildcard matches)."""
    return "|".join(names) or "^$"


# What every efish call of a job is given: the scale and the overrides of its run (capped for the reruns).
ARGS = of_plan(lambda plan: plan.args)
STAGE_ARGS = of_plan(lambda plan: plan.stage_args)
TOP_SEED_ARGS = of_plan(lambda plan: plan.top_seed_args)
# What every plan keeps of its training (the train rule's outputs): the same in every point (efish.sweep).
KEPT_STAGES = next(iter(PLANS.values())).stages.kept


wildcard_constraints:
    run=any_of(map(re.escape, PLANS)),
    seed=r"\d+",
    stage=r"\d+",
    assay=r"[A-Za-z0-9_\-]+",


# ------------------------------------------------------------------ paths: every one from efish.layout
RULE_RUN = Run("{run}")  # the rules' patterns ({run} and the rule's other wildcards)


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


def analysis_outputs(analysis, copy=None):
    """The tables an analysis writes, by name, for the {assay} wildcard (in the copy ``copy``)."""
    return run_plan.analysis_outputs(analysis, RULE_RUN.within(copy))


# ------------------------------------------------------------------ inputs behind the select_seed checkpoint
def recipe_policy(wildcards, name):
    """The final checkpoint of policy ``name`` (a seed's folder or a recipe of config/policy/) in the job's run."""
    return results(training_file(name, "final.pt"), run=Run(wildcards.run))


def seed_policy(wildcards, seed):
    return recipe_policy(wildcards, seed_name(seed))


def stage_policy(run, seed, k):
    """Seed ``seed``'s policy at its k-th kept training stage (train.keep_stages)."""
    return results(training_file(seed_name(seed), stage_file(k)), run=Run(run))


def planned_ranking(wildcards):
    """The seeds in seed order, where a planning dry run (PLANNED_RANKING) finds no ranking yet; else None."""
    if not PLANNED_RANKING or Path(results(RANKING, run=Run(wildcards.run))).exists():
        return None
    if not workflow.dryrun:
        fail("--config planned_ranking=true only counts jobs: give it with --dry-run")
    return list(plan_of(wildcards).cfg.scale.seed_numbers())


def selected_seed(wildcards):
    """The seed the select_seed checkpoint chose."""
    if planned := planned_ranking(wildcards):
        return planned[0]
    return run_plan.selected_seed(checkpoints.select_seed.get(run=wildcards.run).output.seed)


def assay_policies_input(wildcards):
    """The final checkpoint of every policy an assay's conditions act with, by policy name. The ``selected`` policy
    is the seed the select_seed checkpoint chose (at training stage {stage} for a stage's assays), or seed {seed}
    for a top seed's rerun."""
    seed, stage = getattr(wildcards, "seed", None), getattr(wildcards, "stage", None)

    def path(name):
        if name != run_plan.SELECTED:
            return recipe_policy(wildcards, name)
        if stage is not None:
            return stage_policy(wildcards.run, selected_seed(wildcards), stage)
        return seed_policy(wildcards, selected_seed(wildcards) if seed is None else seed)

    return {name: path(name) for name in plan_of(wildcards).policies_of(wildcards.assay)}


def policy_args(wildcards, input):
    """efish assay's --policy entries: NAME=PATH for every input policy."""
    return " ".join(f"{name}={path}" for name, path in input.items())


def top_seeds(wildcards):
    """The ``scale.top_seeds`` best-ranked seeds, from the select_seed checkpoint's ranking table."""
    if planned := planned_ranking(wildcards):
        return planned[:plan_of(wildcards).cfg.scale.top_seeds]
    return run_plan.top_seeds(checkpoints.select_seed.get(run=wildcards.run).output.ranking,
                              plan_of(wildcards).cfg.scale.top_seeds)


def other_top_seeds(wildcards):
    """The top seeds other than the selected one (the ranking's first row), best first: each reruns every claim's
    assay in its own copy of the layout for its own claims table."""
    return top_seeds(wildcards)[1:]


def group_seeds(wildcards):
    """The top seeds that rerun assay {assay}, best first, all in one job (efish.run_plan.RunPlan.group_seeds)."""
    return plan_of(wildcards).group_seeds(wildcards.assay, top_seeds(wildcards))


def group_policies_input(wildcards):
    """The policies of assay {assay}'s group job: the final checkpoint of each seed in it (named seed_<n>) and of
    every recipe its conditions act with (by name)."""
    recipes = [name for name in plan_of(wildcards).policies_of(wildcards.assay) if name != run_plan.SELECTED]
    return {name: recipe_policy(wildcards, name) for name in [*recipes, *map(seed_name, group_seeds(wildcards))]}


def group_args(wildcards, input):
    """efish assay's --policy NAME=PATH of the recipes (if any) and --group SEED=PATH of the seeds."""
    seeds = {seed_name(seed): seed for seed in group_seeds(wildcards)}
    recipes = [f"{name}={path}" for name, path in input.items() if name not in seeds]
    return " ".join([*(["--policy", *recipes] if recipes else []), "--group",
                     *(f"{seed}={input[name]}" for name, seed in seeds.items())])


def seed_draw(wildcards):
    """The draw of the homing recipes top seed {seed} reruns assay {assay} with: k for the k-th top seed, k =
    2..scale.homing_seeds (efish.run_plan.RunPlan.draw_seeds). Another seed (a table asked for by hand) is an error
    naming those that do."""
    draws = plan_of(wildcards).draw_seeds(top_seeds(wildcards))
    if int(wildcards.seed) not in draws:
        raise ValueError(f"seed {wildcards.seed} does not rerun assay {wildcards.assay}; the top seeds that do: "
                         f"{', '.join(map(str, draws)) or 'none'} (scale.homing_seeds)")
    return draws[int(wildcards.seed)]


def draw_policies_input(wildcards):
    """The policies of top seed {seed}'s solo rerun of assay {assay} (acted by recipes alone: homing), by recipe
    name: the final checkpoint of the seed's own draw of each recipe (efish.layout.recipe_draw)."""
    k = seed_draw(wildcards)
    recipes = plan_of(wildcards).policies_of(wildcards.assay)
    return {name: recipe_policy(wildcards, recipe_draw(name, k)) for name in recipes}


def group_of_seed(wildcards):
    """The group folder of assay {assay} that holds seed {seed}'s tables. A seed that does not rerun the assay (a
    table asked for by hand) is an error naming those that do, not a group job that leaves it out."""
    if int(wildcards.seed) not in (seeds := group_seeds(wildcards)):
        raise ValueError(f"seed {wildcards.seed} does not rerun assay {wildcards.assay}; the top seeds that do: "
                         f"{', '.join(map(str, seeds)) or 'none'}")
    return results(top_seed_group(wildcards.assay), run=Run(wildcards.run))


def other_seed_claims(wildcards):
    """The claims tables of the other top seeds, in ranking order (the claims rule combines them)."""
    return [results(CLAIMS_TABLE, top_seed_copy(seed), Run(wildcards.run)) for seed in other_top_seeds(wildcards)]


def other_seed_parts(wildcards):
    """The parts tables of the other top seeds (beside their claims tables; the recipe's verdict reads them)."""
    return [results(CLAIM_PARTS, top_seed_copy(seed), Run(wildcards.run)) for seed in other_top_seeds(wildcards)]


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
    layout (a top seed's homing too where it reruns homing with a draw of its recipes of its own)."""
    copy = copy_of(wildcards)
    plan = plan_of(wildcards)
    if copy is None:
        paths = plan.claim_tables
    elif getattr(wildcards, "seed", None) is not None:
        drawn = bool(plan.draws) and int(wildcards.seed) in plan.draw_seeds(top_seeds(wildcards))
        paths = plan.top_seed_claim_tables(drawn)
    else:
        paths = plan.seed_claim_tables
    return [results(path, copy, Run(wildcards.run)) for path in paths]


# ------------------------------------------------------------------ learning
def stage_policies(wildcards):
    """The selected seed's stage files, k = 1..K (their records hold the env steps trained)."""
    return [stage_policy(wildcards.run, selected_seed(wildcards), k) for k in plan_of(wildcards).stages.kept]


def learning_target(wildcards):
    """The learning target's inputs, every run's; without kept stages one line and no job."""
    try:
        return [path for plan in PLANS.values() for path in plan.stages.targets(Run(plan.run))]
    except run_plan.PlanError as exc:
        fail(str(exc))


def learning_outputs(reported=False):
    """What claims-by-stage writes (efish.run_plan.learning_outputs); ``reported``: each figure's PNG (one per
    figure of the paper's claims) goes into the report, beside the claims."""
    outputs = run_plan.learning_outputs(RULE_RUN)
    if reported:
        for name in [n for n in outputs if n.startswith("png_")]:
            outputs[name] = report(outputs[name], caption="../report/learning.rst", category="Claims")
    return outputs


def power_stages(wildcards):
    """The claims along training, where the run keeps stages (scale.learning): efish power shows each part's effect
    at every stage beside its plan."""
    if not plan_of(wildcards).cfg.scale.learning:
        return []
    outputs = run_plan.learning_outputs(Run(wildcards.run))
    return [outputs["table"], outputs["trends"]]


def power_outputs():
    """What efish power writes (efish.run_plan.power_outputs); its figure's PNG goes into the report, beside the
    claims."""
    outputs = run_plan.power_outputs(RULE_RUN)
    outputs["png"] = report(outputs["png"], caption="../report/power.rst", category="Claims")
    return outputs


# ------------------------------------------------------------------ figures
def report_entry(figure, path):
    """A figure job's output as the report shows it: each panel's PNG under its figure's category with the
    figure's legend, the page's PNG under "Figure pages"; PDFs are not in the report."""
    if not path.endswith(".png"):
        return path
    if Path(path).parent.name == figure:
        return report(path, caption="../report/panel.rst", category=figure, labels={"panel": Path(path).stem})
    return report(path, caption="../report/figure_page.rst", category="Figure pages", labels={"figure": figure})
