# Assays (SPEC 11): one job per assay writes its steps, episodes and food tables.
# An assay is a file config/assay/<name>.yaml; its `policy` key says which
# trained policy acts (the selected seed, or the homing policy).


rule assay:
    input:
        policy=assay_policy,
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
    threads: 1
    conda:
        "../envs/efish.yaml"
    shell:
        "efish assay assay={wildcards.assay} {params.overrides} --policy {input.policy} "
        "--out {params.out} > {log} 2>&1"
