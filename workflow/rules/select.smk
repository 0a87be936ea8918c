# Seed selection (SPEC 10): every seed on held-out patchy episodes, then a
# checkpoint rule ranks them; the assays read the chosen seed from its output.


rule evaluate_seed:
    input:
        "results/{run}/train/seed_{seed}/final.pt",
    output:
        "results/{run}/selection/seed_{seed}/episodes.parquet",
        "results/{run}/selection/seed_{seed}/steps.parquet",
        "results/{run}/selection/seed_{seed}/food.parquet",
    log:
        "results/{run}/logs/selection/seed_{seed}.log",
    benchmark:
        "results/{run}/benchmarks/selection/seed_{seed}.tsv"
    params:
        overrides=ARGS,
        out=folder_of(0),
    threads: 1
    conda:
        "../envs/efish.yaml"
    shell:
        "efish assay assay=selection {params.overrides} --policy {input} "
        "--out {params.out} > {log} 2>&1"


checkpoint select_seed:
    input:
        expand("results/{{run}}/selection/seed_{seed}/episodes.parquet", seed=SEEDS),
    output:
        ranking="results/{run}/analysis/selection/ranking.parquet",
        seed="results/{run}/analysis/selection/selected_seed.txt",
    log:
        "results/{run}/logs/select_seed.log",
    benchmark:
        "results/{run}/benchmarks/select_seed.tsv"
    params:
        overrides=ARGS,
        out=folder_of("ranking"),
    conda:
        "../envs/efish.yaml"
    shell:
        "efish select {params.overrides} --episodes {input} --out {params.out} > {log} 2>&1"
