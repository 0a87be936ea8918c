# Episode clips and the contact sheet: one clip of the first episode of the first condition of each assay of
# scale.clip_assays that the scale runs (efish render), and one page of every panel's thumbnail
# (efish contact-sheet).


rule render_clip:
    input:
        steps=results(assay_table("{assay}", "steps")),
        food=results(assay_table("{assay}", "food")),
        conditions=results(assay_table("{assay}", "conditions")),
    output:
        report(str(RULE_RUN.clip("{assay}")), caption="../report/clip.rst", category="Episodes",
               labels={"assay": "{assay}"}),
    log:
        log("render/{assay}"),
    benchmark:
        benchmark("render/{assay}")
    params:
        overrides=ARGS,
        tables=lambda wildcards, input: str(Path(input.steps).parent),
    wildcard_constraints:
        assay=any_of(across(lambda plan: plan.clip_assays)),
    conda:
        "../envs/efish.yaml"
    shell:
        efish("render", "assay={wildcards.assay} --tables {params.tables} --out {output}")


rule contact_sheet:
    input:
        lambda wildcards: [str(Run(wildcards.run).panel(p.figure, p.name, "png")) for p in plan_of(wildcards).drawable],
    output:
        report(str(RULE_RUN.contact_sheet), caption="../report/contact_sheet.rst", category="Contact sheet"),
    log:
        log("render/contact_sheet"),
    benchmark:
        benchmark("render/contact_sheet")
    params:
        overrides=ARGS,
        figures=folder_of(0),
        drawn=of_plan(lambda plan: len(plan.drawable)),
        registered=len(PANELS),
    conda:
        "../envs/efish.yaml"
    shell:
        efish("contact-sheet", "--figures {params.figures} --out {output}")
