# Claims along training (`snakemake learning`; in the default target where scale.learning is set): at each kept
# training stage (efish.run_plan: RunPlan.stages) the selected seed's stage_<k>.pt acts in every claim's assay,
# the claims' analyses run on them (analysis.smk: stage_analysis_<analysis>) and the claims table is written, all in
# results/{run}/learning/stage_<k>/ (efish.layout.Run.stage). efish claims-by-stage stacks the stages' parts
# (a last stage at fraction 1 is the run's own claims), tests each part's trend against env steps and draws them,
# one figure per figure of the paper's claims (claims_by_stage_fig2 .. _fig6).


use rule assay as stage_assay with:
    output:
        **assay_outputs(hidden=False, copy=STAGE),
    log:
        log("assays/{assay}", STAGE),
    benchmark:
        benchmark("assays/{assay}", STAGE)
    params:
        overrides=STAGE_ARGS,
        out=folder_of("steps"),
        policies=policy_args,
    wildcard_constraints:
        assay=any_of(across(lambda plan: plan.by_hidden(plan.seed_claim_assays, hidden=False))),
        stage=any_of(across(lambda plan: map(str, plan.stages.rerun))),


use rule stage_assay as stage_assay_with_hidden with:
    output:
        **assay_outputs(hidden=True, copy=STAGE),
    wildcard_constraints:
        assay=any_of(across(lambda plan: plan.by_hidden(plan.seed_claim_assays, hidden=True))),
        stage=any_of(across(lambda plan: map(str, plan.stages.rerun))),


use rule claims as stage_claims with:
    input:
        tables=claims_inputs,
    output:
        table=results(CLAIMS_TABLE, STAGE),
        parts=results(CLAIM_PARTS, STAGE),
        page=results(CLAIMS_PAGE, STAGE),
    log:
        log("claims", STAGE),
    benchmark:
        benchmark("claims", STAGE)
    params:
        overrides=ARGS,
        results=folder_of("table", 1),
        seeds="",
        out=folder_of("table"),


rule claims_by_stage:
    input:
        parts=lambda wildcards: plan_of(wildcards).stages.parts(Run(wildcards.run)),
        policies=stage_policies,
        claims=results(CLAIMS_TABLE),
    output:
        **learning_outputs(reported=True),
    log:
        log("learning"),
    benchmark:
        benchmark("learning")
    params:
        overrides=ARGS,
        stages=lambda wildcards, input: run_plan.keyed(KEPT_STAGES, input.parts),
        policies=lambda wildcards, input: run_plan.keyed(KEPT_STAGES, input.policies),
        episodes=of_plan(lambda plan: run_plan.keyed(plan.stages.kept, plan.stages.episodes)),
        out=folder_of("table"),
        figures=folder_of("png_fig2"),
    conda:
        "../envs/efish.yaml"
    shell:
        efish("claims-by-stage", "--stages {params.stages} --stage-policies {params.policies} "
              "--episodes {params.episodes} --claims {input.claims} --out {params.out} --figures {params.figures}")


rule learning:
    input:
        learning_target,
