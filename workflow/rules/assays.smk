# Assays (SPEC 11): one job per assay writes its steps, episodes and food tables (and hidden.parquet where the
# assay sets record_hidden). An assay is a file config/assay/<name>.yaml; each condition's `assay.policy` says which
# trained policy acts (the selected seed, or a recipe of config/policy/), and the job gets every one it needs.


rule assay:
    input:
        unpack(assay_policies_input),
    output:
        steps="results/{run}/assays/{assay}/steps.parquet",
        episodes="results/{run}/assays/{assay}/episodes.parquet",
        food="results/{run}/assays/{assay}/food.parquet",
    log:
        "results/{run}/logs/assays/{assay}.log",
    benchmark:
        "results/{run}/benchmarks/assays/{assay}.tsv"
    params:
        overrides=ARGS,
        out=folder_of("steps"),
        policies=policy_args,
    wildcard_constraints:
        assay="|".join(a for a in ASSAYS if a not in HIDDEN_ASSAYS) or "^$",
    threads: 1
    conda:
        "../envs/efish.yaml"
    shell:
        "efish assay assay={wildcards.assay} {params.overrides} --policy {params.policies} "
        "--out {params.out} > {log} 2>&1"


use rule assay as assay_with_hidden with:
    output:
        steps="results/{run}/assays/{assay}/steps.parquet",
        episodes="results/{run}/assays/{assay}/episodes.parquet",
        food="results/{run}/assays/{assay}/food.parquet",
        hidden="results/{run}/assays/{assay}/hidden.parquet",
    wildcard_constraints:
        assay="|".join(HIDDEN_ASSAYS) or "^$",


# The best-ranked seeds (scale.top_seeds, from the select_seed checkpoint's ranking) rerun assays with their own
# checkpoint as the `selected` policy, into results/{run}/seeds/seed_{seed}/assays/{assay}/ (the layout of
# results/{run}/assays/): every top seed runs scale.top_seed_assays for the supplement's top-seed panels, and each
# top seed other than the selected one also runs every claim's assay (common.smk: SEED_CLAIM_ASSAYS) for its own
# claims table. The selected seed's rules, whose inputs (assay_policies_input) read {seed}.
use rule assay as top_seed_assay with:
    output:
        steps="results/{run}/seeds/seed_{seed}/assays/{assay}/steps.parquet",
        episodes="results/{run}/seeds/seed_{seed}/assays/{assay}/episodes.parquet",
        food="results/{run}/seeds/seed_{seed}/assays/{assay}/food.parquet",
    log:
        "results/{run}/logs/seeds/seed_{seed}/{assay}.log",
    benchmark:
        "results/{run}/benchmarks/seeds/seed_{seed}/{assay}.tsv"
    wildcard_constraints:
        assay="|".join(a for a in TOP_SEED_ASSAYS if a not in TOP_SEED_HIDDEN) or "^$",


use rule top_seed_assay as top_seed_assay_with_hidden with:
    output:
        steps="results/{run}/seeds/seed_{seed}/assays/{assay}/steps.parquet",
        episodes="results/{run}/seeds/seed_{seed}/assays/{assay}/episodes.parquet",
        food="results/{run}/seeds/seed_{seed}/assays/{assay}/food.parquet",
        hidden="results/{run}/seeds/seed_{seed}/assays/{assay}/hidden.parquet",
    wildcard_constraints:
        assay="|".join(TOP_SEED_HIDDEN) or "^$",


# The supplement's top-seed panels: the top seeds' episodes in scale.top_seed_assays, stacked with seed and rank.
rule top_seeds:
    input:
        tables=top_seed_tables,
        ranking="results/{run}/analysis/selection/ranking.parquet",
    output:
        "results/{run}/seeds/{assay}/episodes.parquet",
    log:
        "results/{run}/logs/seeds/{assay}.log",
    conda:
        "../envs/efish.yaml"
    params:
        overrides=ARGS,
    shell:
        "efish stack-seeds {params.overrides} --tables {input.tables} --ranking {input.ranking} --out {output} "
        "> {log} 2>&1"
