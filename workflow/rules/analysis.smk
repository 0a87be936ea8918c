# Analyses (SPEC 12): one rule per analysis of efish.analysis.registry, one job per (analysis, assay), writing
# results/{run}/analysis/<analysis>/{assay}/<table>.parquet (the registry declares every table). The DAG asks
# for the analyses of each assay of the scale whose input tables that assay writes (common.smk: ASSAY_ANALYSES).


for analysis in ANALYSES.values():

    rule:
        name:
            f"analysis_{analysis.name}"
        input:
            **analysis_inputs(analysis),
        output:
            **analysis_outputs(analysis),
        log:
            f"results/{{run}}/logs/analysis/{analysis.name}/{{assay}}.log",
        benchmark:
            f"results/{{run}}/benchmarks/analysis/{analysis.name}/{{assay}}.tsv"
        params:
            overrides=ARGS,
            analysis=analysis.name,
            out=folder_of(analysis.outputs[0]),
        wildcard_constraints:
            assay="|".join(analysis.assays),
        threads: 1
        conda:
            "../envs/efish.yaml"
        shell:
            "efish analyze {params.analysis} assay={wildcards.assay} {params.overrides} "
            "--tables results/{wildcards.run}/assays/{wildcards.assay} --out {params.out} > {log} 2>&1"
