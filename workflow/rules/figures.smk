# Panels: one job per registered panel (efish.figures.registry), one page per figure.


rule panel:
    input:
        lambda w: panel_inputs(panel_of(w)),
    output:
        png=report(
            "figures/{run}/{figure}/{panel}.png",
            caption="../report/panel.rst",
            category="{figure}",
        ),
        pdf="figures/{run}/{figure}/{panel}.pdf",
    log:
        "results/{run}/logs/figures/{figure}_{panel}.log",
    benchmark:
        "results/{run}/benchmarks/figures/{figure}_{panel}.tsv"
    params:
        overrides=ARGS,
        caption=lambda w: panel_of(w).caption,
        tables=lambda w: ", ".join(f"``{path}``" for path in panel_of(w).inputs.values()) or "none (a schematic)",
        out=folder_of("png", up=1),
    wildcard_constraints:
        figure="fig[0-9]+|supp",
    conda:
        "../envs/efish.yaml"
    shell:
        "efish figure {wildcards.figure}/{wildcards.panel} {params.overrides} "
        "--results results/{wildcards.run} --out {params.out} > {log} 2>&1"


rule figure_page:
    input:
        lambda w: [path for p in DRAWABLE if p.figure == w.figure for path in panel_inputs(p)],
    output:
        png=report("figures/{run}/{figure}.png", caption="../report/figure_page.rst", category="Figure pages"),
        pdf="figures/{run}/{figure}.pdf",
    log:
        "results/{run}/logs/figures/{figure}.log",
    benchmark:
        "results/{run}/benchmarks/figures/{figure}.tsv"
    params:
        overrides=ARGS,
        out=folder_of("png"),
        panels=lambda w: ", ".join(p.name for p in DRAWABLE if p.figure == w.figure),
    wildcard_constraints:
        figure="fig[0-9]+|supp",
    conda:
        "../envs/efish.yaml"
    shell:
        "efish figure {wildcards.figure} {params.overrides} "
        "--results results/{wildcards.run} --out {params.out} > {log} 2>&1"
