# Seed selection (SPEC 10): every seed on held-out patchy episodes, then a
# checkpoint rule ranks them; the assays read the chosen seed from its output.


rule evaluate_seed:
    input:
        "results/{scale}/train/seed_{seed}/final.pt",
    output:
        "results/{scale}/selection/seed_{seed}/episodes.parquet",
        "results/{scale}/selection/seed_{seed}/steps.parquet",
        "results/{scale}/selection/seed_{seed}/food.parquet",
    log:
        "results/{scale}/logs/selection/seed_{seed}.log",
    benchmark:
        "results/{scale}/benchmarks/selection/seed_{seed}.tsv"
    params:
        overrides=ARGS,
        out=folder_of(0),
    threads: 1
    conda:
        "../envs/efish.yaml"
    shell:
        "efish assay assay=selection scale={wildcards.scale} {params.overrides} --policy {input} "
        "--out {params.out} > {log} 2>&1"


checkpoint select_seed:
    input:
        expand("results/{{scale}}/selection/seed_{seed}/episodes.parquet", seed=SEEDS),
    output:
        ranking="results/{scale}/analysis/selection/ranking.parquet",
        seed="results/{scale}/analysis/selection/selected_seed.txt",
    log:
        "results/{scale}/logs/select_seed.log",
    benchmark:
        "results/{scale}/benchmarks/select_seed.tsv"
    params:
        overrides=ARGS,
        out=folder_of("ranking"),
    conda:
        "../envs/efish.yaml"
    shell:
        "efish select scale={wildcards.scale} {params.overrides} --episodes {input} --out {params.out} > {log} 2>&1"
