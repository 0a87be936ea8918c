# Stages the points of a sweep share (efish.share): where a later point's config agrees with an earlier one's on all a
# stage depends on (its training; everything but the analysis settings), the jobs of that stage's rules are the
# earlier point's, copied with their provenance by share_<rule> (one per rule of the stage, with the same outputs, for
# the runs it serves; it outranks its rule). A plain run, or a point that shares nothing, builds everything itself.
from snakemake.io import apply_wildcards, strip_wildcard_constraints

from efish import share

SOURCES = {stage.name: stage.sources(list(PLANS.values())) for stage in share.STAGES}


def mirrored(patterns, sources):
    """The input function of a share rule: the job's outputs in the run its run copies the stage from."""
    return lambda wildcards: [apply_wildcards(p, {**dict(wildcards.items()), "run": sources[wildcards.run]})
                              for p in patterns]


for producer in list(workflow.rules):
    patterns = [strip_wildcard_constraints(str(path)) for path in producer.output]
    stage = share.stage_of(patterns)
    sources = SOURCES[stage.name] if stage is not None and not producer.is_checkpoint else {}
    if not sources:
        continue

    rule:
        name:
            f"share_{producer.name}"
        input:
            mirrored(patterns, sources),
        output:
            # the rule's own patterns, but for {run}: the share rule's constraint says which runs it serves
            [re.sub(r"\{run,[^{}]*\}", "{run}", str(path)) for path in producer.output],
        log:
            log(str(Path("share", producer.name, *(f"{{{w}}}" for w in sorted(producer.wildcard_names - {"run"}))))),
        wildcard_constraints:
            run=any_of(map(re.escape, sources)),
        localrule: True
        run:
            share.copy_job(list(input), list(output), log[0])

    workflow.ruleorder(f"share_{producer.name}", producer.name)
