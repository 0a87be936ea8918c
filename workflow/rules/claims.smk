# Claims (CLAIMS.md): one job reading every table the claims registry (efish.analysis.claims.CLAIMS) names that
# this scale produces, writing results/{run}/claims/claims.parquet and claims.md. A claim whose tables the scale
# does not produce is written as "not run" with the missing table named (efish claims never fails on it).
# Verdicts across seeds. Each top seed other than the selected one gets its own claims table
# from its rerun assays (top_seed_claims, results/{run}/seeds/seed_{seed}/claims/); the claims job adds their
# verdicts to the selected seed's as seed_verdicts and seeds_agree ("3/3 hold"), in the ranking's order.


rule claims:
    input:
        tables=claims_inputs,
        ranking="results/{run}/analysis/selection/ranking.parquet",
        seeds=other_seed_claims,
    output:
        table="results/{run}/claims/claims.parquet",
        page=report(
            "results/{run}/claims/claims.md",
            caption="../report/claims.rst",
            category="Claims",
        ),
    log:
        "results/{run}/logs/claims.log",
    benchmark:
        "results/{run}/benchmarks/claims.tsv"
    params:
        overrides=ARGS,
        results=folder_of("table", 1),
        seeds=seed_claims_args,
        out=folder_of("table"),
    threads: 1
    conda:
        "../envs/efish.yaml"
    shell:
        "efish claims {params.overrides} --results {params.results} --out {params.out} {params.seeds} > {log} 2>&1"


use rule claims as top_seed_claims with:
    input:
        tables=claims_inputs,
    output:
        table="results/{run}/seeds/seed_{seed}/claims/claims.parquet",
        page="results/{run}/seeds/seed_{seed}/claims/claims.md",
    log:
        "results/{run}/logs/seeds/seed_{seed}/claims.log",
    benchmark:
        "results/{run}/benchmarks/seeds/seed_{seed}/claims.tsv"
    params:
        overrides=ARGS,
        results=folder_of("table", 1),
        seeds="",
        out=folder_of("table"),
