"""The picture of the rules on docs/architecture.md#workflow names the workflow's rules: adding, renaming or
removing a rule without redrawing it (workflow/rulegraph.sh) fails here. Graphviz is not needed: the rules of
``snakemake --rulegraph`` (DOT text) are compared with the boxes of the committed SVG."""

from __future__ import annotations

import re
import subprocess
import xml.etree.ElementTree as ET
from pathlib import Path

REPO = Path(__file__).resolve().parents[2]
PICTURE = REPO / "docs/img/rulegraph.svg"
SVG = "{http://www.w3.org/2000/svg}"
#: A node of Snakemake's rule graph: ``3[label = "bench_scaling", color = ...]``.
DOT_NODE = re.compile(r'^\s*\d+\s*\[label = "([^"]+)"', re.M)


def dot_rules(dot: str) -> list[str]:
    """The rule names of a ``snakemake --rulegraph`` DOT text."""
    return DOT_NODE.findall(dot)


def svg_rules(svg: Path) -> list[str]:
    """The text of every node box of a Graphviz SVG (the rule names; edges and the graph's title are not nodes)."""
    root = ET.parse(svg).getroot()
    return ["".join(text.itertext()).strip() for node in root.iter(f"{SVG}g") if node.get("class") == "node"
            for text in node.iter(f"{SVG}text")]


def test_the_dot_and_svg_readers_find_the_rules(tmp_path):
    dot = 'digraph snakemake_dag {\n    node[shape=box];\n\t0[label = "all", color = "0.0 0.6 0.85"];\n' \
          '\t1[label = "train", color = "0.6 0.6 0.85", style="rounded"];\n\t1 -> 0\n}\n'
    assert dot_rules(dot) == ["all", "train"]
    (tmp_path / "g.svg").write_text(
        '<svg xmlns="http://www.w3.org/2000/svg"><g class="graph"><title>snakemake_dag</title>'
        '<g class="node"><title>0</title><text>all</text></g><g class="node"><title>1</title><text>train</text></g>'
        '<g class="edge"><title>1&#45;&gt;0</title></g></g></svg>')
    assert svg_rules(tmp_path / "g.svg") == ["all", "train"]


def test_the_committed_rule_graph_names_the_workflows_rules(tmp_path):
    """The rule graph of the laptop scale planned in an empty folder, as workflow/rulegraph.sh draws it."""
    result = subprocess.run(["snakemake", "--rulegraph", "--cores", "1", "--snakefile", str(REPO / "Snakefile"),
                             "--directory", str(tmp_path), "--config", "scale=laptop"],
                            capture_output=True, text=True, timeout=300)
    assert result.returncode == 0, result.stderr[-2000:]
    rules = dot_rules(result.stdout)
    assert len(rules) > 20 and "all" in rules and "select_seed" in rules
    drawn = svg_rules(PICTURE)
    assert len(drawn) == len(set(drawn))
    assert sorted(drawn) == sorted(rules), ("redraw docs/img/rulegraph.svg with workflow/rulegraph.sh: "
                                            f"new rules {sorted(set(rules) - set(drawn))}, "
                                            f"gone {sorted(set(drawn) - set(rules))}")
