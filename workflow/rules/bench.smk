# Speed and accuracy studies of the physics core.


rule bench_physics:
    output:
        "results/{scale}/bench/bench_physics.json",
    log:
        "results/{scale}/logs/bench_physics.log",
    benchmark:
        "results/{scale}/benchmarks/bench_physics.tsv"
    params:
        overrides=ARGS,
        out=folder_of(0),
    threads: 1
    conda:
        "../envs/efish.yaml"
    shell:
        "efish bench physics scale={wildcards.scale} {params.overrides} --out {params.out} > {log} 2>&1"


rule bench_accuracy:
    output:
        table="results/{scale}/bench/bench_accuracy.parquet",
        figure="results/{scale}/bench/bench_accuracy.png",
    log:
        "results/{scale}/logs/bench_accuracy.log",
    benchmark:
        "results/{scale}/benchmarks/bench_accuracy.tsv"
    params:
        overrides=ARGS,
        out=folder_of("table"),
    threads: 1
    conda:
        "../envs/efish.yaml"
    shell:
        "efish bench accuracy scale={wildcards.scale} {params.overrides} --out {params.out} > {log} 2>&1"


rule figure_bench_accuracy:
    input:
        "results/{scale}/bench/bench_accuracy.png",
    output:
        report(
            "figures/{scale}/bench/bench_accuracy.png",
            caption="../report/bench_accuracy.rst",
            category="Benchmarks",
        ),
    log:
        "results/{scale}/logs/figure_bench_accuracy.log",
    conda:
        "../envs/efish.yaml"
    shell:
        "cp {input} {output} 2> {log}"
