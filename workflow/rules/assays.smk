# Assays (SPEC 11): one job per assay writes its steps, episodes and food tables.
# An assay is a file config/assay/<name>.yaml; its `policy` key says which
# trained policy acts (the selected seed, or the homing policy).


rule assay:
    input:
        policy=assay_policy,
    output:
        steps="results/{scale}/assays/{assay}/steps.parquet",
        episodes="results/{scale}/assays/{assay}/episodes.parquet",
        food="results/{scale}/assays/{assay}/food.parquet",
    log:
        "results/{scale}/logs/assays/{assay}.log",
    benchmark:
        "results/{scale}/benchmarks/assays/{assay}.tsv"
    params:
        overrides=ARGS,
        out=folder_of("steps"),
    threads: 1
    conda:
        "../envs/efish.yaml"
    shell:
        "efish assay assay={wildcards.assay} scale={wildcards.scale} {params.overrides} --policy {input.policy} "
        "--out {params.out} > {log} 2>&1"
