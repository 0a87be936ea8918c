# Figures: one job per figure (efish figure <figure>) draws each of its panels registered in
# efish.figures.registry (a PNG and a PDF each, with provenance, so `efish figure fig3/K` can redraw one) and the
# figure's page, loading each panel's tables once. The report lists every panel under its figure's category, with
# the figure's legend: each panel's caption and the tables it reads.


# In a sweep, a figure whose panels differ between points (a scale key that changes what is drawn) gets one rule per
# set of panels, each for the runs that draw that set.


def figure_inputs(figure):
    """The input function of a figure's job: every table its panels read in the job's run."""
    return lambda wildcards: plan_of(wildcards).figure_inputs(figure, Run(wildcards.run))


def figure_legend(figure):
    """The legend of a figure's job (report captions) in the job's run."""
    return lambda wildcards: plan_of(wildcards).figure_legend(figure)


for figure in across(lambda plan: plan.figure_panels):
    drawn = [runs for panels, runs in by_plan(lambda plan: tuple(p.name for p in plan.figure_panels.get(figure, [])))
             if panels]
    for i, runs in enumerate(drawn):

        rule:
            name:
                f"figure_{figure}" if i == 0 else f"figure_{figure}_{i + 1}"
            input:
                figure_inputs(figure),
            output:
                [report_entry(figure, path) for path in PLANS[runs[0]].figure_outputs(figure, RULE_RUN)],
            log:
                log(f"figures/{figure}"),
            benchmark:
                benchmark(f"figures/{figure}")
            params:
                overrides=ARGS,
                figure=figure,
                legend=figure_legend(figure),
                out=lambda wildcards: str(Run(wildcards.run).figures),
                results=lambda wildcards: str(Run(wildcards.run).results),
            wildcard_constraints:
                run=any_of(map(re.escape, runs)),
            conda:
                "../envs/efish.yaml"
            shell:
                # params, not the loop variable: Snakemake evaluates a shell directive when the job runs, after the
                # loop
                efish("figure {params.figure}", "--results {params.results} --out {params.out}")
