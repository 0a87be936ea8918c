"""``efish --help`` is the user's documentation of the command line, so it is held to a standard.

Every (sub)command has a description that ends with the documentation pages to read, every argument and option
has a help line, every page the help names exists (with its anchor) and is titled as the site's navigation titles
it, no help shows the docstrings' reStructuredText, and ``efish --version`` prints the installed version.
"""

from __future__ import annotations

import argparse
import os
import re
import subprocess
import sys
from collections.abc import Iterator
from pathlib import Path

import pytest
import yaml

import efish
from efish.cli import _parser, main
from efish.cli_support import DOC_PAGES, doc_page

from .docs.test_site import anchors

REPO = Path(__file__).resolve().parents[1]
DOC_PATH = re.compile(r"\bdocs/[\w/.-]+?\.md(?:#[\w-]+)?")
RST = re.compile(r"``|:(?:func|mod|class|data|meth|attr):`")


def parsers(parser: argparse.ArgumentParser | None = None, name: str = "efish"
            ) -> Iterator[tuple[str, argparse.ArgumentParser]]:
    """Every parser of the command line, the top level's first, each with its command (``efish bench physics``)."""
    parser = parser or _parser()
    yield name, parser
    for action in parser._actions:
        if isinstance(action, argparse._SubParsersAction):
            for sub_name, sub in action.choices.items():
                yield from parsers(sub, f"{name} {sub_name}")


def documented(parser: argparse.ArgumentParser) -> list[argparse.Action]:
    """The actions of a parser that must say what they are: all but ``-h``, whose help argparse writes."""
    return [a for a in parser._actions if not isinstance(a, argparse._HelpAction)]


def texts(parser: argparse.ArgumentParser) -> list[str]:
    """The help a parser was given: its description, epilog and every argument's help."""
    return [t for t in (parser.description, parser.epilog, *(a.help for a in parser._actions)) if t]


def nav_titles() -> dict[str, str]:
    """``{docs/<page>.md: "Section › Title"}`` from mkdocs.yml's nav (a section's own page gets the section's name)."""
    def walk(entries: list, trail: tuple[str, ...]) -> Iterator[tuple[str, str]]:
        for entry in entries:
            if isinstance(entry, str):
                yield f"docs/{entry}", " › ".join(trail)
                continue
            for title, value in entry.items():
                if isinstance(value, list):
                    yield from walk(value, (*trail, title))
                else:
                    yield f"docs/{value}", " › ".join((*trail, title))
    class Loader(yaml.SafeLoader):
        """mkdocs.yml's ``!ENV [NAME, default]`` read as its default: only the nav matters here."""
    Loader.add_constructor("!ENV", lambda loader, node: loader.construct_sequence(node)[-1])
    return dict(walk(yaml.load((REPO / "mkdocs.yml").read_text(), Loader)["nav"], ()))


ALL = list(parsers())


def test_the_walk_sees_every_command_and_each_bench_study():
    names = [name for name, _ in ALL]
    assert names[0] == "efish" and "efish claims-by-stage" in names and "efish bench" in names
    assert "efish bench group" in names and len(names) == 1 + 21 + 9  # efish, its commands, the bench studies


@pytest.mark.parametrize("name, parser", ALL[1:], ids=[name for name, _ in ALL[1:]])
def test_every_command_says_what_it_does_and_which_pages_to_read(name, parser):
    assert parser.description and parser.description.strip(), name
    assert "\n\ndocs: " in parser.description, f"{name}: no docs: paragraph"


@pytest.mark.parametrize("name, parser", ALL, ids=[name for name, _ in ALL])
def test_every_argument_and_option_has_help(name, parser):
    missing = [a.dest for a in documented(parser) if not (a.help and a.help.strip())]
    assert not missing, f"{name}: no help for {missing}"


def test_every_command_that_takes_overrides_explains_them_in_one_wording():
    overrides = [a.help for _, p in ALL for a in p._actions if a.dest == "overrides" and a.nargs == "*"]
    assert len(overrides) > 15
    assert all(h.startswith("Hydra overrides of the config: key=value or a config group's choice, e.g. ")
               and h.endswith("(efish config lists the keys)") for h in overrides)


def test_every_docs_page_the_help_names_exists_with_its_anchor():
    named = {m for _, p in ALL for text in texts(p) for m in DOC_PATH.findall(text)}
    assert {"docs/claims/index.md", "docs/benchmarks.md#accuracy"} <= named
    missing = []
    for ref in sorted(named):
        page, _, anchor = ref.partition("#")
        if not (REPO / page).is_file() or (anchor and anchor not in anchors(REPO / page)):
            missing.append(ref)
    assert not missing, missing


def test_the_help_names_a_page_by_its_title_in_the_sites_navigation():
    titles = nav_titles()
    assert titles["docs/claims/index.md"] == "Claims › Rules and claims" and titles["docs/benchmarks.md"] == "Benchmarks"
    wrong = {page: (title, titles.get(page)) for page, title in DOC_PAGES.items() if titles.get(page) != title}
    assert not wrong, wrong
    assert doc_page("docs/claims/index.md#rule-4") == "Claims › Rules and claims (docs/claims/index.md#rule-4)"
    missing = "docs/" + "nope.md"  # in two pieces: the site's tests take a whole path in a file for a citation
    with pytest.raises(KeyError, match=f"{missing} is not in efish.cli_support.DOC_PAGES"):
        doc_page(missing)


@pytest.mark.parametrize("name, parser", ALL, ids=[name for name, _ in ALL])
def test_printed_help_keeps_each_docs_path_whole_and_shows_no_restructuredtext(name, parser, monkeypatch):
    """At a narrow terminal a hyphenated path (docs/tutorials/override-configs.md) must not break across lines."""
    monkeypatch.setenv("COLUMNS", "50")
    printed = parser.format_help()
    assert set(DOC_PATH.findall(printed)) == {m for text in texts(parser) for m in DOC_PATH.findall(text)}, name
    assert not RST.search(printed), f"{name}: {RST.search(printed).group(0)!r} in its help"


def test_the_top_level_help_is_plain_text_with_examples_and_the_docs():
    printed = _parser().format_help()
    assert "The ``efish`` command" not in printed and "The command line of efish" in printed
    assert "\nexamples:\n  efish config scale=smoke " in printed
    assert "docs: Reference › Command line (docs/reference/cli.md)" in printed


def test_efish_version_prints_the_installed_version_and_exits_0():
    src = str(Path(efish.__file__).resolve().parents[1])  # the efish under test, not another install
    env = {**os.environ, "PYTHONPATH": os.pathsep.join([src, os.environ.get("PYTHONPATH", "")])}
    done = subprocess.run([sys.executable, "-m", "efish", "--version"], capture_output=True, text=True, env=env,
                          timeout=120)
    assert (done.returncode, done.stdout, done.stderr) == (0, f"efish {efish.__version__}\n", "")


def test_efish_version_from_main(capsys):
    with pytest.raises(SystemExit) as stop:
        main(["--version"])
    assert stop.value.code == 0 and capsys.readouterr().out == f"efish {efish.__version__}\n"
