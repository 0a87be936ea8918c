# Speed and accuracy studies of the physics core: each writes its table under the run's bench/ folder and its
# figure (if it has one) under the run's figures (efish.layout).


rule bench_physics:
    output:
        results(bench_file("bench_physics.json")),
    log:
        log("bench_physics"),
    benchmark:
        benchmark("bench_physics")
    params:
        overrides=ARGS,
        out=folder_of(0),
    conda:
        "../envs/efish.yaml"
    shell:
        efish("bench physics", "--out {params.out}")


rule bench_accuracy:
    output:
        table=results(bench_file("bench_accuracy.parquet")),
        png=report(str(RULE_RUN.bench_figure("bench_accuracy", "png")), caption="../report/bench_accuracy.rst",
                   category="Benchmarks"),
        pdf=str(RULE_RUN.bench_figure("bench_accuracy", "pdf")),
    log:
        log("bench_accuracy"),
    benchmark:
        benchmark("bench_accuracy")
    params:
        overrides=ARGS,
        out=folder_of("table"),
        figures=folder_of("png"),
    conda:
        "../envs/efish.yaml"
    shell:
        efish("bench accuracy", "--out {params.out} --figures {params.figures}")


rule bench_scaling:
    output:
        table=results(bench_file("bench_scaling.parquet")),
        png=report(str(RULE_RUN.bench_figure("bench_scaling", "png")), caption="../report/bench_scaling.rst",
                   category="Benchmarks"),
        pdf=str(RULE_RUN.bench_figure("bench_scaling", "pdf")),
    log:
        log("bench_scaling"),
    benchmark:
        benchmark("bench_scaling")
    params:
        overrides=ARGS,
        out=folder_of("table"),
        figures=folder_of("png"),
    conda:
        "../envs/efish.yaml"
    shell:
        efish("bench scaling", "--out {params.out} --figures {params.figures}")
