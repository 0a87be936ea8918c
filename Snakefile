# efish pipeline: run `snakemake --profile workflow/profiles/default` (laptop scale)
# or add `--config scale=smoke|paper`. Rules call the `efish` CLI; all numbers
# live in config/ and are read by efish, never repeated here.
import os

from snakemake.utils import min_version

min_version("9.0")


# The image every job runs in when the workflow is run with --software-deployment-method apptainer (the profile
# workflow/profiles/slurm-apptainer): efish.sif in the repository's root, built by
# `apptainer build efish.sif container/efish.def`; $EFISH_IMAGE names another (a path, or docker://<registry>/...).
# Without that method Snakemake ignores the directive: the default run uses the environment it was started in.
container: os.environ.get("EFISH_IMAGE", "efish.sif")


report: "workflow/report/workflow.rst"


include: "workflow/rules/common.smk"
include: "workflow/rules/bench.smk"
include: "workflow/rules/train.smk"
include: "workflow/rules/select.smk"
include: "workflow/rules/assays.smk"
include: "workflow/rules/analysis.smk"
include: "workflow/rules/scenes.smk"
include: "workflow/rules/figures.smk"
include: "workflow/rules/render.smk"
include: "workflow/rules/claims.smk"
include: "workflow/rules/learning.smk"
include: "workflow/rules/share.smk"


rule all:
    input:
        [path for plan in PLANS.values() for path in [*plan.targets(Run(plan.run)), *plan.training_targets(Run(plan.run))]],
    default_target: True
