# Analyses (SPEC 12): one rule per analysis of efish.analysis.registry, one job per (analysis, assay), writing
# results/{run}/analysis/<analysis>/{assay}/<table>.parquet (the registry declares every table). The DAG asks
# for the analyses of each assay of the scale whose input tables that assay writes (common.smk: ASSAY_ANALYSES).
# The same rule per analysis, named top_seed_analysis_<analysis>, runs on a top seed's rerun assays into
# results/{run}/seeds/seed_{seed}/analysis/ (the analyses the claims read there; common.smk: seed_analysis_assays).


for analysis in ANALYSES.values():
    variants = [(None, "", analysis.assays), ("{seed}", "top_seed_", seed_analysis_assays(analysis))]
    for seed, prefix, assays in (v for v in variants if v[2]):

        rule:
            name:
                f"{prefix}analysis_{analysis.name}"
            input:
                **analysis_inputs(analysis, seed),
            output:
                **analysis_outputs(analysis, seed=seed),
            log:
                f"results/{{run}}/logs/{seed_folder(seed)}analysis/{analysis.name}/{{assay}}.log",
            benchmark:
                f"results/{{run}}/benchmarks/{seed_folder(seed)}analysis/{analysis.name}/{{assay}}.tsv"
            params:
                overrides=ARGS,
                analysis=analysis.name,
                tables=lambda wildcards, input: str(Path(input[0]).parent),
                out=folder_of(analysis.outputs[0]),
            wildcard_constraints:
                assay="|".join(assays),
            threads: 1
            conda:
                "../envs/efish.yaml"
            shell:
                "efish analyze {params.analysis} assay={wildcards.assay} {params.overrides} "
                "--tables {params.tables} --out {params.out} > {log} 2>&1"
