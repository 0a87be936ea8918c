# Figures: one job per figure (efish figure <figure>) draws each of its panels registered in
# efish.figures.registry (a PNG and a PDF each, with provenance, so `efish figure fig3/K` can redraw one) and the
# figure's page, loading each panel's tables once. The report lists every panel under its figure's category, with
# the figure's legend: each panel's caption and the tables it reads.


for figure in PLAN.figure_panels:

    rule:
        name:
            f"figure_{figure}"
        input:
            PLAN.figure_inputs(figure, THIS_RUN),
        output:
            [report_entry(figure, path) for path in PLAN.figure_outputs(figure, RULE_RUN)],
        log:
            log(f"figures/{figure}"),
        benchmark:
            benchmark(f"figures/{figure}")
        params:
            overrides=PLAN.args,
            figure=figure,
            legend=PLAN.figure_legend(figure),
            out=lambda wildcards: str(Run(wildcards.run).figures),
            results=lambda wildcards: str(Run(wildcards.run).results),
        conda:
            "../envs/efish.yaml"
        shell:
            # params, not the loop variable: Snakemake evaluates a shell directive when the job runs, after the loop
            efish("figure {params.figure}", "--results {params.results} --out {params.out}")
