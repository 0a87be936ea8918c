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
# checkpoint as the `selected` policy, each in its own copy of the layout (efish.layout.Run.top_seed): every top
# seed runs scale.top_seed_assays for the supplement's top-seed panels, and each top seed other than the selected
# one also runs every claim's assay (efish.run_plan: RunPlan.seed_claim_assays) for its own claims table. They are
# the selected seed's rules, whose inputs (assay_policies_input) read {seed}, at scale.top_seed_episodes episodes per
# condition (more seeds at fewer episodes decide the recipe's verdict better: efish.claims.recipe).
use rule assay as top_seed_assay with:
    output:
        **assay_outputs(hidden=False, copy=TOP_SEED),
    params:
        overrides=TOP_SEED_ARGS,
        out=folder_of("steps"),
        policies=policy_args,
    log:
        log("assays/{assay}", TOP_SEED),
    benchmark:
        benchmark("assays/{assay}", TOP_SEED)
    wildcard_constraints:
        assay=any_of(across(lambda plan: plan.by_hidden(plan.top_seed_assays, hidden=False))),


use rule top_seed_assay as top_seed_assay_with_hidden with:
    output:
        **assay_outputs(hidden=True, copy=TOP_SEED),
    wildcard_constraints:
        assay=any_of(across(lambda plan: plan.by_hidden(plan.top_seed_assays, hidden=True))),


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
