# Analyses: one rule per analysis of efish.analysis.registry, one job per (analysis, assay), reading the assay's
# record (its rollout tables and conditions.parquet) and writing the tables the registry declares
# (efish.layout.analysis_table) and the analysis settings it ran with (analysis_settings.parquet, which the
# panels read; Analysis.written). The DAG asks for the analyses of each assay of the scale whose
# input tables that assay writes (efish.run_plan: RunPlan.assay_analyses). The same rule per analysis, named
# top_seed_analysis_<analysis>, runs on a top seed's rerun assays in its copy of the layout (the analyses the
# claims read there, homing's where the seed reruns it with a draw of the homing recipes;
# RunPlan.top_seed_analysis_assays), and stage_analysis_<analysis> on a training stage's (RunPlan.seed_analysis_assays;
# learning.smk).


for analysis in ANALYSES.values():
    variants = [(None, "", analysis.assays),
                (TOP_SEED, "top_seed_", across(lambda plan: plan.top_seed_analysis_assays(analysis))),
                (STAGE, "stage_", across(lambda plan: plan.seed_analysis_assays(analysis) if plan.stages.rerun else []))]
    for copy, prefix, assays in (v for v in variants if v[2]):

        rule:
            name:
                f"{prefix}analysis_{analysis.name}"
            input:
                **analysis_inputs(analysis, copy),
            output:
                **analysis_outputs(analysis, copy),
            log:
                log(f"analysis/{analysis.name}/{{assay}}", copy),
            benchmark:
                benchmark(f"analysis/{analysis.name}/{{assay}}", copy)
            params:
                overrides=ARGS,
                analysis=analysis.name,
                tables=lambda wildcards, input: str(Path(input[0]).parent),
                out=folder_of(analysis.outputs[0]),
            wildcard_constraints:
                assay="|".join(assays),
            conda:
                "../envs/efish.yaml"
            shell:
                efish("analyze {params.analysis}", "assay={wildcards.assay} --tables {params.tables} --out {params.out}")
