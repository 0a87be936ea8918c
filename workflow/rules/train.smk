# Training: every foraging seed of the scale (recipe config/policy/foraging.yaml: the paper's arenas, sampled per
# episode), and every policy recipe an assay asks for
# (config/policy/<name>.yaml composes its task, arenas and training: homing, homing_raycast). efish train
# checkpoints beside the declared output and writes final.pt atomically at the
# end, so a killed job is rerun and resumes from its last checkpoint. A seed also keeps its policy at the
# fractions scale.keep_stages of its training (stage_<k>.pt) for the claims along training (learning.smk).
# The homing claims are decided over scale.homing_seeds draws of the homing recipes: draw 1 is train/<recipe>/,
# draw k >= 2 the same recipe trained again with train.seed seed_offset + k into train/<recipe>_draw_<k>/
# (efish.layout.recipe_draw; RunPlan.draw_trainings), which the k-th top seed reruns homing with (assays.smk).


rule train:
    output:
        final=results(training_file(seed_name("{seed}"), "final.pt")),
        metrics=results(training_file(seed_name("{seed}"), "metrics.parquet")),
        **{stage_name(k): results(training_file(seed_name("{seed}"), stage_file(k))) for k in KEPT_STAGES},
    log:
        log(f"train/{seed_name('{seed}')}"),
    benchmark:
        benchmark(f"train/{seed_name('{seed}')}")
    params:
        overrides=ARGS,
        out=folder_of("final"),
    conda:
        "../envs/efish.yaml"
    shell:
        efish("train", "policy=foraging train.seed={wildcards.seed} train.threads={threads} --out {params.out}")


rule train_policy:
    output:
        final=results(training_file("{policy}", "final.pt")),
        metrics=results(training_file("{policy}", "metrics.parquet")),
    log:
        log("train/{policy}"),
    benchmark:
        benchmark("train/{policy}")
    params:
        overrides=lambda wildcards: plan_of(wildcards).recipe_training(wildcards.policy)[1],
        recipe=lambda wildcards: plan_of(wildcards).recipe_training(wildcards.policy)[0],
        out=folder_of("final"),
    wildcard_constraints:
        policy=any_of(across(lambda plan: [*plan.policy_recipes, *plan.draw_trainings])),
    conda:
        "../envs/efish.yaml"
    shell:
        efish("train", "policy={params.recipe} train.threads={threads} --out {params.out}")
