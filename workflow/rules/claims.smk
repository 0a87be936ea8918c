# Claims (CLAIMS.md): one job reading every table the claims registry (efish.analysis.claims.CLAIMS) names that
# this scale produces, writing results/{run}/claims/claims.parquet and claims.md. A claim whose tables the scale
# does not produce is written as "not run" with the missing table named (efish claims never fails on it).


rule claims:
    input:
        claims_inputs,
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
        out=folder_of("table"),
    threads: 1
    conda:
        "../envs/efish.yaml"
    shell:
        "efish claims {params.overrides} --results results/{wildcards.run} --out {params.out} > {log} 2>&1"
