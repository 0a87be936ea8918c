# Speed and accuracy studies of the physics core.


rule bench_physics:
    output:
        "results/{scale}/bench/bench_physics.json",
    log:
        "results/{scale}/logs/bench_physics.log",
    benchmark:
        "results/{scale}/benchmarks/bench_physics.tsv"
    threads: 1
    shell:
        "efish bench physics scale={wildcards.scale} --out results/{wildcards.scale}/bench > {log} 2>&1"


rule bench_accuracy:
    output:
        table="results/{scale}/bench/bench_accuracy.parquet",
        figure="results/{scale}/bench/bench_accuracy.png",
    log:
        "results/{scale}/logs/bench_accuracy.log",
    benchmark:
        "results/{scale}/benchmarks/bench_accuracy.tsv"
    threads: 1
    shell:
        "efish bench accuracy scale={wildcards.scale} --out results/{wildcards.scale}/bench > {log} 2>&1"


rule figure_bench_accuracy:
    input:
        "results/{scale}/bench/bench_accuracy.png",
    output:
        "figures/{scale}/bench/bench_accuracy.png",
    log:
        "results/{scale}/logs/figure_bench_accuracy.log",
    shell:
        "cp {input} {output} 2> {log}"
