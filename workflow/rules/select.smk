# Seed selection: every seed on held-out patchy episodes, then a checkpoint rule ranks them; the assays read the
# chosen seed from its output.


rule evaluate_seed:
    input:
        results(training_file(seed_name("{seed}"), "final.pt")),
    output:
        [results(selection_table("{seed}", t)) for t in ("episodes", "steps", "food", "conditions")],
    log:
        log(f"selection/{seed_name('{seed}')}"),
    benchmark:
        benchmark(f"selection/{seed_name('{seed}')}")
    params:
        overrides=ARGS,
        out=folder_of(0),
    conda:
        "../envs/efish.yaml"
    shell:
        efish("assay", "assay=selection --policy {input} --out {params.out}")


checkpoint select_seed:
    input:
        lambda wildcards: [results(selection_table(seed, "episodes"), run=Run(wildcards.run))
                           for seed in plan_of(wildcards).seeds],
    output:
        ranking=results(RANKING),
        seed=results(SELECTED_SEED),
    log:
        log("select_seed"),
    benchmark:
        benchmark("select_seed")
    params:
        overrides=ARGS,
        out=folder_of("ranking"),
    conda:
        "../envs/efish.yaml"
    shell:
        efish("select", "--episodes {input} --out {params.out}")
