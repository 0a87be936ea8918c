"""MkDocs hooks of the efish site: reference pages generated from the code, and LaTeX turned into MathML.

A page asks for a generated part with a marker on its own line, ``<!-- efish:config -->``,
``<!-- efish:tables -->`` or ``<!-- efish:cli -->``; the marker is replaced when the site is built, so the
reference can never drift from the schema, the table declarations or the argument parser.

Equations are written as LaTeX (a fenced ``math`` block for display, ``$...$`` inline) and converted to
MathML here, which browsers render natively: the built site shows equations without JavaScript or network.
"""

from __future__ import annotations

import argparse
import dataclasses
import html
import re
from pathlib import Path
from typing import Any

from latex2mathml.converter import convert

# --------------------------------------------------------------------- the config reference


def _range(meta: dict) -> str:
    """The allowed values of a field as the schema's ``param(...)`` declares them."""
    if meta.get("choices"):
        return " / ".join(f"`{c}`" for c in meta["choices"])
    lo, hi = meta.get("lo"), meta.get("hi")
    if lo is None and hi is None:
        return ""
    if hi is None:
        return f"&ge; {lo:g}"
    return f"&le; {hi:g}" if lo is None else f"[{lo:g}, {hi:g}]"


def _cell(text: str) -> str:
    """Plain text safe inside a Markdown table cell (no HTML, pipes or emphasis)."""
    return html.escape(text, quote=False).replace("|", "\\|").replace("*", "\\*").replace("_", "\\_")


def _value(value: Any) -> str:
    text = repr(value) if isinstance(value, str) else str(value)
    text = text if len(text) <= 40 else text[:37] + "..."
    return f"`{text}`".replace("|", "\\|")


def config_fields(node: Any = None, path: str = "") -> list[tuple[str, Any, dict]]:
    """Every leaf field of the composed default config: (dotted key, default value, the ``param`` metadata)."""
    from efish.config import compose

    node = compose([]) if node is None else node
    rows = []
    for f in dataclasses.fields(node):
        value, key = getattr(node, f.name), f"{path}{f.name}"
        if dataclasses.is_dataclass(value):
            rows += config_fields(value, f"{key}.")
        else:
            rows.append((key, value, dict(f.metadata)))
    return rows


def config_reference() -> str:
    """Markdown: one table per config group (its keys relative to the group), every field with its default
    (the laptop scale's), allowed range and doc."""
    from efish.config import compose

    cfg, out = compose([]), []
    for group in dataclasses.fields(cfg):
        node = getattr(cfg, group.name)
        doc = " ".join((type(node).__doc__ or "").split())
        out += [f"## `{group.name}` {{#{group.name}}}", "", doc, "",
                "| key | default | allowed | meaning |", "|---|---|---|---|"]
        for key, value, meta in config_fields(node):  # keys relative to the group, which heads the table
            neutral = " *(cannot change a training result)*" if meta.get("neutral") else ""
            text = _cell(meta.get("doc", ""))
            out.append(f"| `{key}` | {_value(value)} | {_range(meta)} | {text}{neutral} |")
        out.append("")
    return "\n".join(out)


# --------------------------------------------------------------------- the tables reference


def _codes(columns) -> str:
    return ", ".join(f"`{c}`" for c in columns)


def tables_reference() -> str:
    """Markdown: the columns of every rollout table (``efish schema``), of the analysis settings table and of the
    claims tables."""
    from efish.analysis.registry import ANALYSES
    from efish.analysis.selection import RANKING_COLUMNS
    from efish.claims.planner import CURVE_COLUMNS, PLAN_COLUMNS, STAGE_PLAN_COLUMNS
    from efish.claims.power_page import CLAIM_SUMMARY_COLUMNS
    from efish.claims.recipe import RECIPE_COLUMNS, RECIPE_PART_COLUMNS
    from efish.claims.seeds import SEED_COLUMNS
    from efish.claims.verdicts import PART_COLUMNS, ROW_COLUMNS
    from efish.config.recorded import SETTINGS_COLUMN
    from efish.layout import ANALYSIS_SETTINGS, analysis_settings
    from efish.rollout.schema import COLUMNS, HIDDEN_UNITS

    out = []
    for name, columns in COLUMNS.items():
        out += [f"## `{name}.parquet` {{#{name}}}", "", f"`efish schema {name}` prints this list.", "",
                "| column | type | meaning |", "|---|---|---|"]
        out += [f"| `{col}` | `{typ}` | {_cell(doc)} |" for col, typ, doc in columns]
        if name == "hidden":
            out.append(f"| `h_0`, `h_1`, ... | `float` | {html.escape(HIDDEN_UNITS)} |")
        out.append("")
    out += ["## The analysis tables {#analysis-tables}", "",
            "Every analysis writes these tables under `results/{run}/analysis/<analysis>/<assay>/` for each assay "
            "it belongs to (`efish.analysis.registry.ANALYSES`); their columns and how each is computed are on "
            "[the analyses page](../methods/analyses.md).", "",
            "| analysis | reads | assays | tables |", "|---|---|---|---|"]
    out += [f"| [`{a.name}`](../methods/analyses.md#analysis-{a.name}) | {_codes(a.reads)} | {_codes(a.assays)} | "
            f"{_codes(a.outputs)} |" for a in ANALYSES.values()]
    out.append("")
    out += [f"## `{ANALYSIS_SETTINGS}.parquet`: the settings an analysis job ran with {{#analysis-settings}}", "",
            f"`efish analyze` writes it beside the tables of every analysis of an assay "
            f"(`{analysis_settings('<analysis>', '<assay>')}`): one row, whose `{SETTINGS_COLUMN}` column holds "
            "the `analysis` config group the job ran with (every field, the run's overrides included) as JSON. "
            "`efish.config.recorded.recorded_settings` reads it back; the panels read it for the thresholds they "
            "name, which are those the tables were computed under. What the run simulated (frame rate, arena, "
            "roles) is not in it: the analysis read that from the assay's `conditions.parquet`.", ""]
    with_seeds = [*ROW_COLUMNS[:2], *RECIPE_COLUMNS, *ROW_COLUMNS[2:-1], *SEED_COLUMNS, ROW_COLUMNS[-1]]
    claims_note = (f"The pipeline's table (with the top seeds' verdicts and the recipe's): {_codes(with_seeds)}. "
                   "Meanings: [the claims page](../claims/index.md#what-a-row-holds).")
    for title, anchor, columns, note in (
            ("`claims.parquet`: one row per claim", "claims", ROW_COLUMNS, claims_note),
            ("`claim_parts.parquet`: one row per part of a claim", "claim-parts", PART_COLUMNS, ""),
            ("`recipe_parts.parquet`: one row per part, decided over the top seeds", "recipe-parts",
             RECIPE_PART_COLUMNS, "How: [the recipe's verdict](../claims/index.md#the-recipes-verdict)."),
            ("`power.parquet`: what a decisive verdict costs, one row per part", "power", PLAN_COLUMNS,
             f"Where the run kept training stages, also {_codes(STAGE_PLAN_COLUMNS)}. "
             "Meanings: [what a verdict costs](../claims/power.md#columns)."),
            ("`power_curves.parquet`: the chances per part and design", "power-curves", CURVE_COLUMNS,
             "The figure's rows: [what a verdict costs](../claims/power.md#figure)."),
            ("`power_claims.parquet`: what would settle each claim", "power-claims", CLAIM_SUMMARY_COLUMNS,
             "Meanings: [what a verdict costs](../claims/power.md#by-claim)."),
            ("`ranking.parquet`: the seed ranking", "ranking", RANKING_COLUMNS, "")):
        out += [f"## {title} {{#{anchor}}}", "", _codes(columns), ""] + ([note, ""] if note else [])
    return "\n".join(out)


# --------------------------------------------------------------------- the command-line reference


def _subcommands(parser: argparse.ArgumentParser) -> dict[str, argparse.ArgumentParser]:
    """A parser's subcommands by name (none for a leaf command)."""
    actions = [a for a in parser._actions if isinstance(a, argparse._SubParsersAction)]
    return dict(actions[0].choices) if actions else {}


def _docs_read(parser: argparse.ArgumentParser) -> list[str]:
    """The documentation pages a command's help cites (its description, epilog and arguments' help), once each and
    in order, as Markdown links titled as the site's navigation titles them (efish.cli_support.DOC_PAGES)."""
    from efish.cli_support import DOC_PAGES

    texts = [parser.description, parser.epilog, *(a.help for a in parser._actions)]
    paths = dict.fromkeys(m.group(0) for text in texts if text for m in DOC_REFERENCE.finditer(text))
    return [f"[{DOC_PAGES[path.partition('#')[0]]}]({path})" for path in paths]


def _command_reference(name: str, parser: argparse.ArgumentParser, level: int) -> list[str]:
    """Markdown lines of one command: its help as argparse prints it, the pages it cites as links (the help sits in a
    code block, where no link can be), then its subcommands one heading level down."""
    anchor = "-".join(name.split()[1:]) or "efish"
    out = [f"{'#' * level} `{name}` {{#{anchor}}}", "", "```text", parser.format_help().rstrip(), "```", ""]
    if pages := _docs_read(parser):
        out += ["Read: " + "; ".join(pages) + ".", ""]
    child_level = level if name == "efish" else level + 1  # the commands beside efish, a command's studies below
    for sub_name, sub in _subcommands(parser).items():
        out += _command_reference(f"{name} {sub_name}", sub, child_level)
    return out


def cli_reference() -> str:
    """Markdown: ``efish --help`` and every (sub)command's help, as argparse prints them (``bench`` studies as
    subsections of ``efish bench``), each followed by links to the pages it cites."""
    from efish.cli import _parser

    return "\n".join(_command_reference("efish", _parser(), 2))


GENERATED = {"config": config_reference, "tables": tables_reference, "cli": cli_reference}

# --------------------------------------------------------------------- LaTeX to MathML

FENCE = re.compile(r"^(?P<indent> *)(?P<fence>```+|~~~+)(?P<info>[^\n]*)\n(?P<body>.*?)^(?P=indent)(?P=fence)[ \t]*$",
                   re.M | re.S)
INLINE_CODE = re.compile(r"(`+)(?:.+?)\1", re.S)
INLINE_MATH = re.compile(r"(?<![\\$\w])\$(?=\S)(?P<tex>[^$\n]+?)(?<=\S)\$(?![\w$])")


def mathml(tex: str, display: bool) -> str:
    """The LaTeX ``tex`` as one line of MathML (block or inline)."""
    markup = convert(tex.strip(), display="block" if display else "inline")
    return markup.replace("\n", "")


class MathStash:
    """LaTeX swapped for plain-word tokens before Markdown parses a page, and MathML swapped back in after.

    MathML is HTML, and Markdown reads a source line that starts with an HTML tag as a raw HTML block: an
    equation at the start of a line would end the paragraph or list item it sits in. A token is a plain word, so
    the page's blocks (lists, paragraphs, tables) are parsed as if the equation were any other word.
    """

    def __init__(self, page_id: int) -> None:
        self.prefix = f"efishmath{page_id}x"
        self.markup: list[str] = []

    def token(self, tex: str, display: bool) -> str:
        """A token standing for ``tex``; its MathML is kept until :meth:`restore`."""
        self.markup.append(f'<div class="math">{mathml(tex, True)}</div>' if display else mathml(tex, False))
        return f"{self.prefix}{len(self.markup) - 1}z"

    def restore(self, html_text: str) -> str:
        """The page's HTML with every token replaced by its MathML (a display token's paragraph by the block)."""
        def swap(m: re.Match) -> str:
            return self.markup[int(m["index"])]
        token = rf"{self.prefix}(?P<index>\d+)z"
        html_text = re.sub(rf"<p>{token}</p>", swap, html_text)
        return re.sub(token, swap, html_text)


def _inline_math(text: str, stash: MathStash) -> str:
    """``$...$`` outside inline code spans to tokens."""
    def math(m: re.Match) -> str:
        return stash.token(m["tex"], display=False)

    parts, last = [], 0
    for code in INLINE_CODE.finditer(text):
        parts += [INLINE_MATH.sub(math, text[last:code.start()]), code.group(0)]
        last = code.end()
    parts.append(INLINE_MATH.sub(math, text[last:]))
    return "".join(parts)


def stash_math(markdown: str, stash: MathStash) -> str:
    """Fenced ``math`` blocks and inline ``$...$`` to tokens of ``stash``; other code blocks are left as they are.

    A display block becomes a token on a line of its own, at the fence's indent, so that it stays inside the list
    item it was written in."""
    out, last = [], 0
    for block in FENCE.finditer(markdown):
        out.append(_inline_math(markdown[last:block.start()], stash))
        if block["info"].strip() == "math":
            out.append(f'{block["indent"]}{stash.token(block["body"], display=True)}\n')
        else:
            out.append(block.group(0))
        last = block.end()
    out.append(_inline_math(markdown[last:], stash))
    return "".join(out)


# --------------------------------------------------------------------- the hook MkDocs calls

MARKER = re.compile(r"^<!-- efish:(\w+) -->$", re.M)
DOC_REFERENCE = re.compile(r"\bdocs/(?P<page>[\w/-]+\.md)(?P<anchor>#[\w-]+)?")


LINK_TO_DOCS = re.compile(r"\]\(" + DOC_REFERENCE.pattern + r"\)")


def link_docs(markdown: str, page_path: str) -> str:
    """The code's ``docs/<page>.md#anchor`` references, outside code blocks, as links relative to ``page_path``: a
    bare one becomes a link titled by its page, a Markdown link to one (``[title](docs/<page>.md)``) keeps its title."""
    depth = page_path.count("/")

    def target(m: re.Match) -> str:
        return "../" * depth + m["page"] + (m["anchor"] or "")

    def outside_code(text: str) -> str:
        text = LINK_TO_DOCS.sub(lambda m: f"]({target(m)})", text)  # first: its target then no longer says docs/
        return DOC_REFERENCE.sub(lambda m: f"[{m['page'].removesuffix('.md')}]({target(m)})", text)

    out, last = [], 0
    for block in FENCE.finditer(markdown):
        out += [outside_code(markdown[last:block.start()]), block.group(0)]
        last = block.end()
    out.append(outside_code(markdown[last:]))
    return "".join(out)


_STASHES: dict[str, MathStash] = {}
REPO = Path(__file__).resolve().parents[1]
#: Files of the repository's root that a page shows whole (``<!-- efish:changelog -->``).
ROOT_FILES = {"changelog": "CHANGELOG.md"}


def root_file(name: str) -> str:
    """A root file's Markdown for a page at the root of docs/: its links name ``docs/<page>.md`` so that they work
    where the file is read on its own (the repository), and drop ``docs/`` on the page. Only link targets change,
    not paths quoted as code."""
    return (REPO / ROOT_FILES[name]).read_text().replace("](docs/", "](")


def on_page_markdown(markdown: str, page: Any, config: Any, files: Any) -> str:
    """Fill the generated parts a page asks for, then set its math aside as tokens (see :class:`MathStash`)."""
    def generated(match: re.Match) -> str:
        if match[1] in ROOT_FILES:
            return root_file(match[1])
        if match[1] not in GENERATED:
            raise ValueError(f"{page.file.src_path}: unknown generated part {match[1]!r} "
                             f"(known: {', '.join([*GENERATED, *ROOT_FILES])})")
        return link_docs(GENERATED[match[1]](), page.file.src_path)
    stash = _STASHES[page.file.src_path] = MathStash(len(_STASHES))
    return stash_math(MARKER.sub(generated, markdown), stash)


def on_page_content(html_text: str, page: Any, config: Any, files: Any) -> str:
    """Put the page's equations, as MathML, where their tokens are."""
    stash = _STASHES.pop(page.file.src_path, None)
    return html_text if stash is None else stash.restore(html_text)
