"""How to cite efish: CITATION.cff (what citation tools read), the docs' BibTeX and the package agree on what
efish is, its version and year, and the licence they name is the LICENSE file's."""

from __future__ import annotations

import re
import tomllib

import yaml

from .test_site import REPO

CFF = yaml.safe_load((REPO / "CITATION.cff").read_text())
PYPROJECT = tomllib.loads((REPO / "pyproject.toml").read_text())["project"]


def efish_bibtex() -> dict[str, str]:
    """The fields of cite.md's @software{efish, ...} entry."""
    entry = re.search(r"@software\{efish,(.*?)\n\}", (REPO / "docs" / "cite.md").read_text(), re.S)
    assert entry, "docs/cite.md has no @software{efish, ...} BibTeX entry"
    return {k: re.sub(r"\s+", " ", v) for k, v in re.findall(r"(\w+)\s*=\s*\{(.*?)\},?\n(?=\s*\w+\s*=|$)",
                                                              entry.group(1) + "\n", re.S)}


def test_the_citation_file_has_what_a_bibtex_entry_needs():
    """cffconvert's BibTeX takes its year from date-released and its version from version: both present."""
    assert CFF["cff-version"] == "1.2.0" and CFF["type"] == "software"
    assert CFF["title"].startswith("efish: ") and CFF["authors"]
    assert re.fullmatch(r"\d{4}-\d{2}-\d{2}", str(CFF["date-released"]))
    assert CFF["preferred-citation"]["identifiers"][0]["value"] == "arXiv:2511.08436"


def test_version_year_and_licence_agree_everywhere():
    bibtex = efish_bibtex()
    assert CFF["version"] == PYPROJECT["version"] == bibtex["version"]
    assert str(CFF["date-released"])[:4] == bibtex["year"]  # the year the docs give
    assert CFF["license"] == bibtex["license"] == "MIT"
    assert PYPROJECT["license"] == {"text": "MIT"}
    assert (REPO / "LICENSE").read_text().startswith("MIT License")
    assert re.sub(r"\s+", " ", CFF["title"]) == bibtex["title"].replace("{MARL}", "MARL")
