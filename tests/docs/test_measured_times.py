"""The times the front pages quote come from one file, docs/measured-times.yml, so they cannot drift apart."""

from __future__ import annotations

import re

import yaml

from .test_site import DOCS, REPO

QUOTING_PAGES = (REPO / "README.md", DOCS / "index.md", DOCS / "troubleshooting.md")  # the pages a newcomer reads first
QUOTE = re.compile(r"(?:about|~) ?(\d+(?:\.\d+)?(?:[-–]\d+(?:\.\d+)?)? ?(?:minutes|min|hours|h))\b")


def measured() -> dict[str, dict]:
    return yaml.safe_load((DOCS / "measured-times.yml").read_text())


def normal(quote: str) -> str:
    """``~4 min`` and ``about 4 minutes`` alike: the number and a spelled-out unit."""
    number, unit = re.match(r"([\d.–-]+) ?(\w+)", quote).groups()
    return f"{number.replace('–', '-')} " + {"min": "minutes", "h": "hours"}.get(unit, unit)


def test_every_quoted_time_is_a_measured_one():
    allowed = {entry["quote"] for entry in measured().values()}
    stray = [f"{page.relative_to(REPO)}: about {quote}" for page in QUOTING_PAGES
             for quote in QUOTE.findall(page.read_text()) if normal(quote) not in allowed]
    assert not stray, f"not in docs/measured-times.yml: {stray}"


def test_the_readme_quotes_every_measured_time_with_how_it_was_measured_on_record():
    readme = {normal(q) for q in QUOTE.findall((REPO / "README.md").read_text())}
    for name, entry in measured().items():
        assert entry["quote"] in readme, name
        assert re.search(r"20\d\d-\d\d-\d\d", entry["measured"]) and re.search(r"EPYC|Xeon", entry["measured"]), name


def test_a_stale_quote_is_caught():
    assert QUOTE.findall("the laptop run, about 45 minutes on 2 cores; smoke ~4 min") == ["45 minutes", "4 min"]
    assert normal("45 minutes") not in {entry["quote"] for entry in measured().values()}
