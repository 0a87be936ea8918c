# Figures: one job per figure (efish figure <figure>) draws each of its panels registered in
# efish.figures.registry (a PNG and a PDF each, with provenance, so `efish figure fig3/K` can redraw one) and the
# figure's page, loading each panel's tables once. The report lists every panel under its figure's category, with
# the figure's legend: each panel's caption and the tables it reads.


def figure_legend(figure):
    """(panel, caption, tables) of every panel of ``figure`` drawn at this scale, for the report's captions."""
    return [(p.name, p.caption, ", ".join(f"``{path}``" for path in p.inputs.values()) or "none (a schematic)")
            for p in FIGURE_PANELS[figure]]


def report_entry(figure, path):
    """A figure job's output as the report shows it: each panel's PNG under its figure's category with the
    figure's legend, the page's PNG under "Figure pages"; PDFs are not in the report."""
    if not path.endswith(".png"):
        return path
    if Path(path).parent.name == figure:
        return report(path, caption="../report/panel.rst", category=figure, labels={"panel": Path(path).stem})
    return report(path, caption="../report/figure_page.rst", category="Figure pages", labels={"figure": figure})


for figure, panels in FIGURE_PANELS.items():

    rule:
        name:
            f"figure_{figure}"
        input:
            sorted({path for p in panels for path in panel_inputs(p)}),
        output:
            [report_entry(figure, path) for path in figure_outputs(figure)],
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
        conda:
            "../envs/efish.yaml"
        shell:
            # params, not the loop variable: Snakemake evaluates a shell directive when the job runs, after the loop
            efish("figure {params.figure}", "--results {params.results} --out {params.out}")
