"""A griffe extension for the API reference: efish's docstrings, written to read well in ``help()`` and to run as
doctests, turned into the Markdown mkdocstrings renders.

Three habits of the docstrings need it: doctest examples (``>>>`` lines, which Markdown would read as nested
quotes) become fenced ``pycon`` blocks; Sphinx roles (``:func:`x```) become inline code; and a paragraph that is a
list of ``name: type  # meaning`` lines (a dataclass's fields) keeps its lines, as a code block.
"""

from __future__ import annotations

import re
from typing import Any

import griffe

ROLE = re.compile(r":(?:func|class|meth|mod|data|attr|obj|exc):`~?(?:[\w.]+\.)?([^`]+)`")
FIELD_LINE = re.compile(r"^[A-Za-z_][\w, ]*: \S")
PROMPT = re.compile(r"^(>>>|\.\.\.)( |$)")


def _paragraphs(lines: list[str]) -> list[list[str]]:
    """Lines grouped into paragraphs (runs of non-blank lines); blank lines are their own groups."""
    groups: list[list[str]] = []
    for line in lines:
        if not line.strip() or not groups or not groups[-1][-1].strip():
            groups.append([line])
        else:
            groups[-1].append(line)
    return groups


def markdown_docstring(text: str) -> str:
    """The docstring ``text`` with doctests fenced, roles as code and field lists kept line by line."""
    out = []
    for group in _paragraphs(ROLE.sub(r"`\1`", text).splitlines()):
        stripped = [line.strip() for line in group]
        first_prompt = next((i for i, line in enumerate(stripped) if PROMPT.match(line)), None)
        if first_prompt is not None:  # prose that leads into an example stays prose
            out += [*group[:first_prompt], *([""] if first_prompt else []), "```pycon", *group[first_prompt:], "```"]
        elif len(group) > 1 and all(FIELD_LINE.match(line) for line in stripped):
            out += ["```text", *group, "```"]
        else:
            out += group
    return "\n".join(out)


class MarkdownDocstrings(griffe.Extension):
    """Rewrite every object's docstring with :func:`markdown_docstring` once it is loaded."""

    def on_object(self, *, obj: griffe.Object, **kwargs: Any) -> None:
        if obj.docstring is not None:
            obj.docstring.value = markdown_docstring(obj.docstring.value)
