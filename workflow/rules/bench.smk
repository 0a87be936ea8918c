# Speed and accuracy studies of the physics core.


rule bench_physics:
    output:
        "results/{run}/bench/bench_physics.json",
    log:
        "results/{run}/logs/bench_physics.log",
    benchmark:
        "results/{run}/benchmarks/bench_physics.tsv"
    params:
        overrides=ARGS,
        out=folder_of(0),
    threads: 1
    conda:
        "../envs/efish.yaml"
    shell:
        "efish bench physics {params.overrides} --out {params.out} > {log} 2>&1"


rule bench_accuracy:
    output:
        table="results/{run}/bench/bench_accuracy.parquet",
        figure="results/{run}/bench/bench_accuracy.png",
    log:
        "results/{run}/logs/bench_accuracy.log",
    benchmark:
        "results/{run}/benchmarks/bench_accuracy.tsv"
    params:
        overrides=ARGS,
        out=folder_of("table"),
    threads: 1
    conda:
        "../envs/efish.yaml"
    shell:
        "efish bench accuracy {params.overrides} --out {params.out} > {log} 2>&1"


rule figure_bench_accuracy:
    input:
        "results/{run}/bench/bench_accuracy.parquet",
    output:
        png=report(
            "figures/{run}/bench/bench_accuracy.png",
            caption="../report/bench_accuracy.rst",
            category="Benchmarks",
        ),
        pdf="figures/{run}/bench/bench_accuracy.pdf",
    log:
        "results/{run}/logs/figure_bench_accuracy.log",
    benchmark:
        "results/{run}/benchmarks/figures/bench_accuracy.tsv"
    params:
        overrides=ARGS,
        out=folder_of("png", up=1),
    conda:
        "../envs/efish.yaml"
    shell:
        "efish figure bench/accuracy {params.overrides} --results results/{wildcards.run} --out {params.out} "
        "> {log} 2>&1"


rule bench_scaling:
    output:
        table="results/{run}/bench/bench_scaling.parquet",
        png=report(
            "results/{run}/bench/bench_scaling.png",
            caption="../report/bench_scaling.rst",
            category="Benchmarks",
        ),
        pdf="results/{run}/bench/bench_scaling.pdf",
    log:
        "results/{run}/logs/bench_scaling.log",
    benchmark:
        "results/{run}/benchmarks/bench_scaling.tsv"
    params:
        overrides=ARGS,
        out=folder_of("table"),
    threads: 1
    conda:
        "../envs/efish.yaml"
    shell:
        "efish bench scaling {params.overrides} --out {params.out} > {log} 2>&1"
