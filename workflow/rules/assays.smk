# Assays: one job per assay writes its steps, episodes, food and conditions tables (and hidden.parquet where the
# assay sets record_hidden). An assay is a file config/assay/<name>.yaml; each condition's `assay.policy` says which
# trained policy acts (the selected seed, or a recipe of config/policy/), and the job gets every one it needs.


rule assay:
    input:
        unpack(assay_policies_input),
    output:
        **assay_outputs(hidden=False),
    log:
        log("assays/{assay}"),
    benchmark:
        benchmark("assays/{assay}")
    params:
        overrides=ARGS,
        out=folder_of("steps"),
        policies=policy_args,
    wildcard_constraints:
        assay=any_of(across(lambda plan: plan.by_hidden(plan.buildable_assays, hidden=False))),
    conda:
        "../envs/efish.yaml"
    shell:
        efish("assay", "assay={wildcards.assay} --policy {params.policies} --out {params.out}")


use rule assay as assay_with_hidden with:
    output:
        **assay_outputs(hidden=True),
    wildcard_constraints:
        assay=any_of(across(lambda plan: plan.by_hidden(plan.buildable_assays, hidden=True))),


# The best-ranked seeds (scale.top_seeds, from the select_seed checkpoint's ranking) rerun assays with their own
# checkpoint as the `selected` policy, at scale.top_seed_episodes episodes per condition (more seeds at fewer episodes
# decide the recipe's verdict better: efish.claims.recipe), each into its own copy of the layout
# (efish.layout.Run.top_seed): every top seed runs scale.top_seed_assays for the supplement's top-seed panels, and
# each top seed other than the selected one also runs every claim's assay (efish.run_plan: RunPlan.seed_claim_assays,
# RunPlan.group_seeds) for its own claims table.
#
# All the seeds that rerun an assay roll out in one job and one env (efish assay --group,
# docs/methods/assays.md#grouped-rollouts): one start-up instead of one per seed, each seed's tables those of its
# run alone (efish.rollout.group). The job writes them into a temporary folder, one seed_<n>/ per seed
# (efish.layout.top_seed_group), not into the seeds' copies: the seeds are known only once the checkpoint has run
# while a rule's outputs are fixed patterns, and Snakemake removes a job's outputs before it runs.
rule top_seed_group:
    input:
        unpack(group_policies_input),
    output:
        temp(directory(results(top_seed_group("{assay}")))),
    log:
        log(top_seed_group("{assay}")),
    benchmark:
        benchmark(top_seed_group("{assay}"))
    params:
        overrides=TOP_SEED_ARGS,
        policies=group_args,
        out=lambda wildcards, output: str(Path(output[0]) / seed_name("{member}")),
    wildcard_constraints:
        assay=any_of(across(lambda plan: plan.top_seed_assays)),
    conda:
        "../envs/efish.yaml"
    shell:
        efish("assay", "assay={wildcards.assay} {params.policies} --out '{params.out}'")


# Each seed's tables from its group's folder into its copy of the layout, where every later rule and the user read
# them: hard links (a copy where the file system has none), so a job costs no Python start-up and no copying; a
# local rule, so a cluster does not queue it. No benchmark: there is nothing to time. Snakemake touches the links
# once made, and so their group's files, but a directory output's time is that of its own flag file
# (.snakemake_timestamp), so the group does not look newer than the seeds' tables it gave.
rule top_seed_assay:
    input:
        group_of_seed,
    output:
        **assay_outputs(hidden=False, copy=TOP_SEED),
    log:
        log("assays/{assay}", TOP_SEED),
    params:
        tables=lambda wildcards, input: str(Path(input[0]) / seed_name(wildcards.seed)),
        out=folder_of("steps"),
    wildcard_constraints:
        assay=any_of(across(lambda plan: plan.by_hidden(plan.top_seed_assays, hidden=False))),
    localrule: True
    shell:
        "(ln -fv {params.tables}/* {params.out} || cp -fv {params.tables}/* {params.out}) > {log} 2>&1"


use rule top_seed_assay as top_seed_assay_with_hidden with:
    output:
        **assay_outputs(hidden=True, copy=TOP_SEED),
    wildcard_constraints:
        assay=any_of(across(lambda plan: plan.by_hidden(plan.top_seed_assays, hidden=True))),


# The homing claims over several draws of the homing recipes (scale.homing_seeds): the homing assay acts with the
# recipes alone, so a top seed's rerun with the run's own recipes would give the selected seed's tables again.
# Instead the k-th top seed (k = 2..scale.homing_seeds, ranking order) reruns it with the k-th draw of the recipes
# (train/<recipe>_draw_<k>/, train.smk; RunPlan.draw_seeds), in its copy of the layout, so each such copy is one
# draw of the whole recipe (its foraging seed and its homing policies) and its claims carry homing verdicts for the
# recipe's verdict over the top seeds. A group job gives every member one policy of its own and homing acts with
# two (--policy homing=... homing_raycast=...), so each seed's rerun is a job of its own, as the run's assay job is.
use rule assay as top_seed_recipe_assay with:
    input:
        unpack(draw_policies_input),
    output:
        **assay_outputs(hidden=False, copy=TOP_SEED),
    log:
        log("assays/{assay}", TOP_SEED),
    benchmark:
        benchmark("assays/{assay}", TOP_SEED)
    params:
        overrides=TOP_SEED_ARGS,
        out=folder_of("steps"),
        policies=policy_args,
    wildcard_constraints:
        assay=any_of(across(lambda plan: plan.by_hidden(plan.drawn_assays, hidden=False))),


use rule top_seed_recipe_assay as top_seed_recipe_assay_with_hidden with:
    output:
        **assay_outputs(hidden=True, copy=TOP_SEED),
    wildcard_constraints:
        assay=any_of(across(lambda plan: plan.by_hidden(plan.drawn_assays, hidden=True))),


# The supplement's top-seed panels: the top seeds' episodes in scale.top_seed_assays, stacked with seed and rank.
rule top_seeds:
    input:
        tables=top_seed_tables,
        ranking=results(RANKING),
    output:
        results(stacked_seeds_table("{assay}")),
    log:
        log("seeds/{assay}"),
    benchmark:
        benchmark("seeds/{assay}")
    params:
        overrides=ARGS,
    conda:
        "../envs/efish.yaml"
    shell:
        efish("stack-seeds", "--tables {input.tables} --ranking {input.ranking} --out {output}")
