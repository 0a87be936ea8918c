"""The fenced code blocks of the project's Markdown pages, as the tests that run the documentation read them.

``tests/docs/test_tutorials.py`` runs every block of the tutorials; ``tests/workflow/test_readme_commands.py``
runs every command the README and the getting-started page show, in an environment with only the README's install.
"""

from __future__ import annotations

import re
import shlex
from dataclasses import dataclass
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]
RUN = ("bash", "python")
SHOWN = ("text", "console")

FENCE = re.compile(r"^(?P<indent>[ \t]*)(?P<fence>`{3,})(?P<info>[^`\n]*)\n(?P<body>.*?)^(?P=indent)(?P=fence)[ \t]*$",
                   re.M | re.S)
FENCE_LINE = re.compile(r"^[ \t]*`{3,}", re.M)
TITLE = re.compile(r'\btitle\s*=\s*"(?P<title>[^"]*)"')
#: What joins commands on one shell line; each side is a command of its own.
SEPARATORS = frozenset({"&&", ";", "||"})


@dataclass(frozen=True)
class Block:
    """One fenced code block of a page: its language, its ``title`` (None: untitled), its text and its line."""

    page: str  # the page's path relative to the repository
    line: int
    lang: str
    title: str | None
    code: str

    @property
    def kind(self) -> str:
        """``write`` (a titled block: a file), ``run`` (bash, python), ``shown`` (output) or ``unknown``."""
        if self.title is not None:
            return "write"
        return "run" if self.lang in RUN else "shown" if self.lang in SHOWN else "unknown"

    @property
    def where(self) -> str:
        return f"{self.page}:{self.line}"


def blocks(page: Path) -> list[Block]:
    """The fenced code blocks of ``page`` in order (a block indented under an admonition or a tab is dedented)."""
    text = page.read_text()
    name = str(page.resolve().relative_to(REPO)) if page.resolve().is_relative_to(REPO) else page.name
    found = []
    for m in FENCE.finditer(text):
        info, indent = m["info"].strip(), m["indent"]
        lang = info.split()[0].lstrip(".").lower() if info else ""
        title = TITLE.search(info)
        body = "".join(line[len(indent):] if line.startswith(indent) else line.lstrip(" \t")
                       for line in m["body"].splitlines(keepends=True))
        found.append(Block(name, text.count("\n", 0, m.start()) + 1, lang, title["title"] if title else None, body))
    return found


def commands(code: str) -> list[str]:
    """The logical lines of a shell block (backslash continuations joined, comments and blank lines dropped)."""
    joined = re.sub(r"\\\n\s*", " ", code)
    return [line.strip() for line in joined.splitlines() if line.strip() and not line.strip().startswith("#")]


def simple_commands(code: str) -> list[list[str]]:
    """Every simple command of a shell block as its words, quotes removed: ``a && b; c  # note`` is ``[a], [b],
    [c]``. For blocks of plain commands (no pipes, redirections or substitutions: a reader copies those)."""
    found = []
    for line in commands(code):
        lexer = shlex.shlex(line, posix=True, punctuation_chars=";&|")
        lexer.whitespace_split, lexer.commenters = True, "#"
        words: list[str] = []
        for token in lexer:
            if token in SEPARATORS:
                found.append(words)
                words = []
            else:
                words.append(token)
        found.append(words)
    return [words for words in found if words]
