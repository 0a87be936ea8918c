# Field maps of Fig 1 and the sensing-range supplement, computed by the physics (config/scene/<scene>.yaml).
# Panels read the scenes' tables (efish.layout.scene_table), so a figure's job asks for the scenes it draws.


rule scene:
    output:
        results(scene_table("{scene}")),
    log:
        log("scenes/{scene}"),
    benchmark:
        benchmark("scenes/{scene}")
    params:
        overrides=ARGS,
        out=folder_of(0),
    wildcard_constraints:
        scene=r"[A-Za-z0-9_\-]+",
    conda:
        "../envs/efish.yaml"
    shell:
        efish("scene {wildcards.scene}", "--out {params.out}")
