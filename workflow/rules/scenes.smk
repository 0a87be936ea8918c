# Field maps of Fig 1 and the sensing-range supplement, computed by the physics (config/scene/<scene>.yaml).
# Panels read results/{run}/scenes/<scene>.parquet, so the panel rule asks for the scenes it draws.


rule scene:
    output:
        "results/{run}/scenes/{scene}.parquet",
    log:
        "results/{run}/logs/scenes/{scene}.log",
    benchmark:
        "results/{run}/benchmarks/scenes/{scene}.tsv"
    params:
        overrides=ARGS,
        out=folder_of(0),
    wildcard_constraints:
        scene=r"[A-Za-z0-9_\-]+",
    threads: 1
    conda:
        "../envs/efish.yaml"
    shell:
        "efish scene {wildcards.scene} {params.overrides} --out {params.out} > {log} 2>&1"
