"""The documentation site stands alone and cannot drift from the code.

The reference pages are generated (docs/hooks.py) from the config schema, the table declarations and
the argument parser: these tests check that the generated text lists every field, column and command.
Every ``docs/<page>.md#<anchor>`` the code cites must name a page and an anchor that exist, and no file
of the project may cite the design documents the project was first written from (they are not in the
repository) or a README section (the README is one screen; the docs carry the detail).
"""

from __future__ import annotations

import dataclasses
import importlib.util
import re
from pathlib import Path

import pytest
from markdown.extensions.toc import slugify

from efish.cli import _parser
from efish.config.schema import EfishConfig
from efish.rollout.schema import COLUMNS

REPO = Path(__file__).resolve().parents[2]
DOCS = REPO / "docs"
SOURCES = ("src", "tests", "workflow", "config", "docs", "Snakefile", "README.md", "CHANGELOG.md", "mkdocs.yml",
           "pyproject.toml", "environment.yml", ".ci")
TEXT_SUFFIXES = {".py", ".md", ".smk", ".yaml", ".yml", ".rst", ".toml", ".sh", ".txt", ""}


def _load(name: str):
    """A Python file of docs/ (the site's build code), loaded as a module."""
    spec = importlib.util.spec_from_file_location(f"efish_docs_{name}", DOCS / f"{name}.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


HOOKS = _load("hooks")
DOCSTRINGS = _load("griffe_docstrings")


def project_files():
    """Every text file of the project that a user reads or runs (sources, configs, rules, docs)."""
    for name in SOURCES:
        path = REPO / name
        paths = [path] if path.is_file() else sorted(p for p in path.rglob("*") if p.is_file())
        yield from (p for p in paths if p.suffix in TEXT_SUFFIXES and "__pycache__" not in p.parts)


def schema_keys(cls=EfishConfig, prefix: str = "") -> set[str]:
    """Every leaf key of the schema, walked from the dataclasses themselves (not from the generator)."""
    keys = set()
    for f in dataclasses.fields(cls):
        sub = f.default_factory if f.default_factory is not dataclasses.MISSING else None
        if sub is not None and isinstance(sub, type) and dataclasses.is_dataclass(sub):
            keys |= schema_keys(sub, f"{prefix}{f.name}.")
        else:
            keys.add(f"{prefix}{f.name}")
    return keys


def test_the_config_reference_lists_every_field_of_the_schema_and_nothing_else():
    sections = HOOKS.config_reference().split("## `")[1:]
    listed = {f"{section.split('`')[0]}.{key}" for section in sections
              for key in re.findall(r"^\| `([\w.]+)` \|", section, re.M)}
    keys = schema_keys()
    assert len(keys) > 200
    assert listed == keys, (sorted(keys - listed)[:10], sorted(listed - keys)[:10])


def test_the_config_reference_gives_each_fields_doc_and_range():
    text = HOOKS.config_reference()
    row = re.search(r"^\| `image_order` \| `1` \| \[0, 3\] \| wall image order.*\|$", text, re.M)
    assert row, "physics.image_order: default 1, range [0, 3] and its doc"
    assert re.search(r"^\| `perception` \| `'electric'` \| `electric` / `raycast` \|", text, re.M)


def test_the_tables_reference_lists_every_column_of_every_rollout_table():
    text = HOOKS.tables_reference()
    for table, columns in COLUMNS.items():
        section = text.split(f"## `{table}.parquet`")[1].split("\n## ")[0]
        assert [c for c, *_ in columns] == re.findall(r"^\| `(\w+)` \|", section, re.M), table


def test_the_cli_reference_has_every_command_with_its_help():
    text = HOOKS.cli_reference()
    commands = next(a for a in _parser()._actions if hasattr(a, "choices") and isinstance(a.choices, dict)).choices
    for name, sub in commands.items():
        assert f"## `efish {name}`" in text and sub.format_usage().split()[1] in text, name
    assert "### `efish bench physics` {#bench-physics}" in text  # a study under its command
    assert "Read: [Claims › Rules and claims](docs/claims/index.md); [Claims › Results](docs/claims/results.md)." in text


def test_a_markdown_link_to_a_docs_page_keeps_its_title_and_gets_a_relative_target():
    text = "Read: [Claims › Results](docs/claims/results.md#stability); bare docs/benchmarks.md.\n"
    out = HOOKS.link_docs(text, "reference/cli.md")
    assert out == "Read: [Claims › Results](../claims/results.md#stability); bare [benchmarks](../benchmarks.md).\n"


def test_math_becomes_mathml_outside_code_only():
    page = "Gain $k_{cons}$, not `$HOME`.\n\n```math\nE = \\frac{q}{r^2}\n```\n\n```bash\necho $HOME $x$\n```\n"
    stash = HOOKS.MathStash(0)
    tokens = HOOKS.stash_math(page, stash)
    assert "<math" not in tokens and "`$HOME`" in tokens and "echo $HOME $x$" in tokens
    out = stash.restore(tokens)
    assert out.count("<math") == 2 and 'display="block"' in out and "<mfrac>" in out


def test_the_codes_docs_references_become_links_in_generated_pages_outside_code():
    text = "Sources (docs/model/physics.md#field-sources).\n```text\nsee docs/model/physics.md\n```\n"
    out = HOOKS.link_docs(text, "reference/config.md")
    assert out.startswith("Sources ([model/physics](../model/physics.md#field-sources)).")
    assert "see docs/model/physics.md" in out


def test_docstrings_become_markdown_with_fenced_doctests_roles_as_code_and_field_lines_kept():
    text = ("Rank seeds with :func:`~efish.analysis.selection.rank_seeds`.\n\nagent_xy: float64[N, 2]  # cm\n"
            "agent_size: float64[N]  # in [0, 1]\n\nFor example:\n>>> 1 + 1\n2\n\nA prose line: with a colon.")
    out = DOCSTRINGS.markdown_docstring(text).split("\n")
    assert out[0] == "Rank seeds with `rank_seeds`."
    assert out[2:6] == ["```text", "agent_xy: float64[N, 2]  # cm", "agent_size: float64[N]  # in [0, 1]", "```"]
    assert out[7:12] == ["For example:", "", "```pycon", ">>> 1 + 1", "2"] and out[12] == "```"
    assert out[-1] == "A prose line: with a colon."


def test_an_unknown_generated_part_stops_the_build_naming_it():
    class Page:
        class file:
            src_path = "reference/x.md"
    with pytest.raises(ValueError, match="reference/x.md: unknown generated part 'nope'"):
        HOOKS.on_page_markdown("<!-- efish:nope -->\n", Page, None, None)


# ------------------------------------------------------------------ the project cites only itself

# Spelled in pieces so that this file does not match itself.
OLD_FORMS = re.compile(r"\b" + "SP" + r"EC\b|\b" + "DES" + r"IGN\b|" + "CLA" + r"IMS\.md|\b" + "CLA" + r"IMS (rule|C\d)|"
                       + "READ" + r"ME[ ,]+\"|\.\./" + "shared")
ISSUE_NUMBER = re.compile(r"\b[Ii]ssues? #?\d+")


def test_no_file_cites_documents_outside_the_repository_or_readme_sections():
    found = [f"{p.relative_to(REPO)}:{i}: {line.strip()[:80]}" for p in project_files()
             for i, line in enumerate(p.read_text(errors="replace").splitlines(), 1) if OLD_FORMS.search(line)]
    assert not found, "\n".join(found[:20])


def test_the_docs_cite_no_issue_numbers():
    pages = [*DOCS.rglob("*.md"), REPO / "README.md", REPO / "CHANGELOG.md"]
    found = [f"{p.relative_to(REPO)}: {m.group(0)}" for p in pages for m in ISSUE_NUMBER.finditer(p.read_text())]
    assert not found, found[:20]


def anchors(page: Path) -> set[str]:
    """The ids a page's headings get: an explicit ``{#id}``, else the heading's text slugified as mkdocs does."""
    ids = set()
    for heading in re.findall(r"^#{1,6} (.+)$", page.read_text(), re.M):
        explicit = re.search(r"\{[^}]*#([\w-]+)[^}]*\}\s*$", heading)
        ids.add(explicit.group(1) if explicit else slugify(re.sub(r"[`*]", "", heading), "-"))
    if "<!-- efish:" in page.read_text():  # a generated page: its headings exist once the site is built
        ids |= {f"{m}" for m in (re.findall(r"\{#([\w-]+)\}", "\n".join(g() for g in HOOKS.GENERATED.values())))}
    return ids


DOC_REFERENCE = re.compile(r"\bdocs/([\w/-]+\.md)(?:#([\w-]+))?")


def test_every_docs_reference_in_the_code_names_a_page_and_anchor_that_exist():
    missing = []
    for path in project_files():
        if path.is_relative_to(DOCS):
            continue  # pages link each other relatively; mkdocs --strict checks those links
        for page, anchor in DOC_REFERENCE.findall(path.read_text(errors="replace")):
            target = DOCS / page
            if not target.is_file():
                missing.append(f"{path.relative_to(REPO)}: docs/{page}")
            elif anchor and anchor not in anchors(target):
                missing.append(f"{path.relative_to(REPO)}: docs/{page}#{anchor}")
    assert not missing, "\n".join(sorted(set(missing))[:30])


def test_every_page_of_the_site_is_in_its_navigation():
    nav = (REPO / "mkdocs.yml").read_text()
    pages = {str(p.relative_to(DOCS)) for p in DOCS.rglob("*.md")}
    assert pages and all(page in nav for page in pages), sorted(p for p in pages if p not in nav)


def test_the_changelog_page_links_the_docs_pages_the_changelog_names_and_keeps_quoted_paths():
    text = HOOKS.root_file("changelog")
    assert "](docs/" not in text and "](benchmarks.md)" in text
    assert "`docs/" in (REPO / "CHANGELOG.md").read_text() and "`docs/" in text  # code keeps the repository path
