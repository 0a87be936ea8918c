# Episode clips and the contact sheet: one clip of the first episode of the first condition of each assay in
# CLIP_ASSAYS that the scale runs (efish render), and one page of every panel's thumbnail (efish contact-sheet).


rule render_clip:
    input:
        steps="results/{run}/assays/{assay}/steps.parquet",
        food="results/{run}/assays/{assay}/food.parquet",
    output:
        report(
            "figures/{run}/clips/{assay}.gif",
            caption="../report/clip.rst",
            category="Episodes",
            labels={"assay": "{assay}"},
        ),
    log:
        "results/{run}/logs/render/{assay}.log",
    benchmark:
        "results/{run}/benchmarks/render/{assay}.tsv"
    params:
        overrides=ARGS,
        condition=clip_condition,
        tables=lambda wildcards, input: str(Path(input.steps).parent),
    wildcard_constraints:
        assay="|".join(CLIP_ASSAYS) or "^$",
    conda:
        "../envs/efish.yaml"
    shell:
        "efish render assay={wildcards.assay} {params.overrides} --condition {params.condition:q} "
        "--tables {params.tables} --out {output} > {log} 2>&1"


rule contact_sheet:
    input:
        [f"figures/{{run}}/{p.figure}/{p.name}.png" for p in DRAWABLE],
    output:
        report("figures/{run}/contact_sheet.png", caption="../report/contact_sheet.rst", category="Contact sheet"),
    log:
        "results/{run}/logs/render/contact_sheet.log",
    benchmark:
        "results/{run}/benchmarks/render/contact_sheet.tsv"
    params:
        overrides=ARGS,
        figures=folder_of(0),
        drawn=len(DRAWABLE),
        registered=len(PANELS),
    conda:
        "../envs/efish.yaml"
    shell:
        "efish contact-sheet {params.overrides} --figures {params.figures} --out {output} > {log} 2>&1"
