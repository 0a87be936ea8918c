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


TEST_COUNT = re.compile(r"(\d{1,3}(?:,\d{3})+|\d+) tests\b")


def test_the_ci_time_and_its_test_count_on_the_architecture_page_are_the_measured_ones():
    """The architecture page's CI paragraph quotes the same run as measured-times.yml: its minutes and its count of
    tests (the last number before "tests" in each)."""
    entry = measured()["tests"]["measured"]
    page = (DOCS / "architecture.md").read_text()
    paragraph = page[page.index("`.ci/run` on a clean clone of commit"):]
    paragraph = paragraph.split("\n\n")[0]  # to the paragraph's end (or the page's)
    assert TEST_COUNT.findall(paragraph)[-1] in TEST_COUNT.findall(entry), (paragraph[:200], entry)
    minutes = re.search(r"took (\d+(?:\.\d+)?) min", paragraph).group(1)
    assert f"{minutes} min" in entry, (minutes, entry)
