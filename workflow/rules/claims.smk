# Claims: one job reading every table the claims registry (efish.claims.CLAIMS) names that this scale
# produces, writing claims.parquet, claim_parts.parquet (one row per tested part) and claims.md. A claim whose tables the scale does not produce is written as
# "not run" with the missing table named (efish claims never fails on it).
# Verdicts across seeds. Each top seed other than the selected one gets its own claims table from its rerun assays
# (top_seed_claims, in its copy of the layout); the claims job adds their verdicts to the selected seed's as
# seed_verdicts and seeds_agree ("3/3 hold"), in the ranking's order, and decides each part over all top seeds
# (recipe_parts.parquet; the claims table's recipe_* columns: efish.claims.recipe).


rule claims:
    input:
        tables=claims_inputs,
        ranking=results(RANKING),
        seeds=other_seed_claims,
        seed_parts=other_seed_parts,
    output:
        table=results(CLAIMS_TABLE),
        parts=results(CLAIM_PARTS),
        recipe=results(RECIPE_PARTS),
        page=report(results(CLAIMS_PAGE), caption="../report/claims.rst", category="Claims"),
    log:
        log("claims"),
    benchmark:
        benchmark("claims")
    params:
        overrides=ARGS,
        results=folder_of("table", 1),
        seeds=seed_claims_args,
        out=folder_of("table"),
    conda:
        "../envs/efish.yaml"
    shell:
        efish("claims", "--results {params.results} --out {params.out} {params.seeds}")


use rule claims as top_seed_claims with:
    input:
        tables=claims_inputs,
    output:
        table=results(CLAIMS_TABLE, TOP_SEED),
        parts=results(CLAIM_PARTS, TOP_SEED),
        page=results(CLAIMS_PAGE, TOP_SEED),
    log:
        log("claims", TOP_SEED),
    benchmark:
        benchmark("claims", TOP_SEED)
    params:
        overrides=ARGS,
        results=folder_of("table", 1),
        seeds="",
        out=folder_of("table"),


# What a decisive verdict costs (efish power, efish.claims.planner): each part planned over the top seeds' claim_parts
# and priced with this run's benchmark files, which every job before it has written. No verdict reads it.
rule power:
    input:
        parts=results(CLAIM_PARTS),
        recipe=results(RECIPE_PARTS),
        ranking=results(RANKING),
        seed_parts=other_seed_parts,
        stages=power_stages,
    output:
        **power_outputs(),
    log:
        log("power"),
    benchmark:
        benchmark("power")
    params:
        overrides=ARGS,
        results=folder_of("table", 1),
        out=folder_of("table"),
        figures=folder_of("png"),
    conda:
        "../envs/efish.yaml"
    shell:
        efish("power", "--results {params.results} --out {params.out} --figures {params.figures}")
