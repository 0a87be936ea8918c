"""What a reader of the built site would see broken, read from its HTML with the standard library's parser.

Markdown decides blocks (paragraphs, list items) before anything else: an equation, a tag or a marker in the wrong
place shows up in the HTML as an element outside every block, or as a list marker left in a paragraph's text.
"""

from __future__ import annotations

import re
from dataclasses import dataclass, field
from html.parser import HTMLParser

# Elements that hold running text: an equation inside one of them reads as part of a sentence.
TEXT_BLOCKS = {"p", "li", "td", "th", "dd", "dt", "figcaption", "h1", "h2", "h3", "h4", "h5", "h6", "summary"}
VOID = {"area", "base", "br", "col", "embed", "hr", "img", "input", "link", "meta", "source", "track", "wbr"}
LIST_MARKER = re.compile(r"^\s*(\d+\.|[-*+]) \S", re.M)
# What an equation the build did not convert leaves in the text: a $ delimiter or a LaTeX command (\hat, \frac).
LEFTOVER_TEX = re.compile(r"\$|\\[A-Za-z]{2,}")


@dataclass
class PageProblems(HTMLParser):
    """Parse one page; ``problems`` lists each defect once with a few words of context."""

    problems: list[str] = field(default_factory=list)
    stack: list[tuple[str, str]] = field(default_factory=list)  # (tag, class) from the root

    def __post_init__(self) -> None:
        super().__init__(convert_charrefs=True)

    def _inside(self, *tags: str) -> bool:
        return any(tag in tags for tag, _ in self.stack)

    def handle_starttag(self, tag: str, attrs: list[tuple[str, str | None]]) -> None:
        classes = dict(attrs).get("class") or ""
        if tag == "math" and not self._inside("math"):
            in_display = any(t == "div" and "math" in c.split() for t, c in self.stack)
            if not in_display and not self._inside(*TEXT_BLOCKS):  # the page's text, or a navigation label
                self.problems.append("an equation outside every paragraph, list item or table cell")
        if tag not in VOID:
            self.stack.append((tag, classes))

    def handle_endtag(self, tag: str) -> None:
        for depth in range(len(self.stack) - 1, -1, -1):  # tolerate unclosed children, as browsers do
            if self.stack[depth][0] == tag:
                del self.stack[depth:]
                return

    def handle_data(self, data: str) -> None:
        if "efishmath" in data:
            self.problems.append(f"an equation's placeholder left in the text: {data.strip()[:60]!r}")
        if self._inside("pre", "code", "script", "style", "math", "textarea"):
            return
        if self._inside("article") and self._inside("p", "li") and (marker := LIST_MARKER.search(data)):
            self.problems.append(f"a list marker in running text: {data[marker.start():].strip()[:60]!r}")
        if self._inside("article") and (tex := LEFTOVER_TEX.search(data)):
            self.problems.append(f"LaTeX left unconverted: {data[max(0, tex.start() - 20):tex.end() + 20].strip()!r}")


def page_problems(html_text: str) -> list[str]:
    """The defects of one built page (empty when it reads right)."""
    parser = PageProblems()
    parser.feed(html_text)
    parser.close()
    return parser.problems
