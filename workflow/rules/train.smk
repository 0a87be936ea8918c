# Training: every foraging seed of the scale, and the homing policy
# (config/policy/homing.yaml composes its task, arenas and training). efish train
# checkpoints beside the declared output and writes final.pt atomically at the
# end, so a killed job is rerun and resumes from its last checkpoint.


rule train:
    output:
        final="results/{run}/train/seed_{seed}/final.pt",
        metrics="results/{run}/train/seed_{seed}/metrics.parquet",
    log:
        "results/{run}/logs/train/seed_{seed}.log",
    benchmark:
        "results/{run}/benchmarks/train/seed_{seed}.tsv"
    params:
        overrides=ARGS,
        out=folder_of("final"),
    threads: 1
    conda:
        "../envs/efish.yaml"
    shell:
        "efish train train.seed={wildcards.seed} train.threads={threads} "
        "{params.overrides} --out {params.out} > {log} 2>&1"


rule train_homing:
    output:
        final="results/{run}/train/homing/final.pt",
        metrics="results/{run}/train/homing/metrics.parquet",
    log:
        "results/{run}/logs/train/homing.log",
    benchmark:
        "results/{run}/benchmarks/train/homing.tsv"
    params:
        overrides=ARGS,
        out=folder_of("final"),
    threads: 1
    conda:
        "../envs/efish.yaml"
    shell:
        "efish train policy=homing train.threads={threads} "
        "{params.overrides} --out {params.out} > {log} 2>&1"
