# Claims (CLAIMS.md): one job reading every table the claims registry (efish.analysis.claims.CLAIMS) names that
# this scale produces, writing results/{run}/claims/claims.parquet and claims.md. A claim whose tables the scale
# does not produce is written as "not run" with the missing table named (efish claims never fails on it).
from efish.analysis.claims import claim_tables, produced_tables


def claims_inputs(wildcards):
    """The claims' tables among those the assays of this scale write (rollout tables and their analyses)."""
    produced = produced_tables({name: assay_config(name).assay for name in ASSAYS})
    return [f"results/{wildcards.run}/{path}" for path in claim_tables() if path in produced]


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
