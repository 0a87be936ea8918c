# Shared settings and target lists.
SCALES = ["smoke", "laptop", "paper"]
SCALE = config.get("scale", "laptop")
if SCALE not in SCALES:
    raise ValueError(f"unknown scale {SCALE!r}: choose one of {', '.join(SCALES)}")


wildcard_constraints:
    scale="|".join(SCALES),


def all_targets():
    """Every final output of the pipeline at the chosen scale."""
    return [
        f"results/{SCALE}/bench/bench_physics.json",
        f"results/{SCALE}/bench/bench_accuracy.parquet",
        f"figures/{SCALE}/bench/bench_accuracy.png",
    ]
