# Training: every foraging seed of the scale, and every policy recipe an assay asks for
# (config/policy/<name>.yaml composes its task, arenas and training: homing, homing_raycast). efish train
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


rule train_policy:
    output:
        final="results/{run}/train/{policy}/final.pt",
        metrics="results/{run}/train/{policy}/metrics.parquet",
    log:
        "results/{run}/logs/train/{policy}.log",
    benchmark:
        "results/{run}/benchmarks/train/{policy}.tsv"
    params:
        overrides=ARGS,
        out=folder_of("final"),
    wildcard_constraints:
        policy="|".join(POLICY_RECIPES),
    threads: 1
    conda:
        "../envs/efish.yaml"
    shell:
        "efish train policy={wildcards.policy} train.threads={threads} "
        "{params.overrides} --out {params.out} > {log} 2>&1"
