#!/usr/bin/env bash
# The picture of the workflow's rules on docs/architecture.md#workflow, from the root of a checkout:
#   workflow/rulegraph.sh [OUT.svg]          (default docs/img/rulegraph.svg; needs graphviz's dot)
# It draws `snakemake --rulegraph` of the laptop scale, planned in an empty folder so that no earlier run's
# outputs change the graph: one box per rule, an arrow where a rule's output is another's input, left to right
# (rankdir=LR: the page is narrower than the graph is wide). The rules that wait on the select_seed checkpoint's
# choice (top_seed_group, top_seed_assay, top_seed_analysis_<name>, top_seed_claims) are planned only once it has
# run, so they are not drawn. tests/workflow/test_rulegraph.py checks that the committed picture names the
# workflow's rules.
set -euo pipefail
cd "$(dirname "$0")/.."
out=${1:-docs/img/rulegraph.svg}
command -v dot >/dev/null || { echo "rulegraph: graphviz's dot is not installed" >&2; exit 1; }
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
snakemake --rulegraph --cores 1 --snakefile "$PWD/Snakefile" --directory "$work" --config scale=laptop > "$work/rulegraph.dot"
dot -Tsvg -Grankdir=LR "$work/rulegraph.dot" > "$work/rulegraph.svg"
mv "$work/rulegraph.svg" "$out"
echo "rulegraph: wrote $out"
