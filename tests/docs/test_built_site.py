"""The built site, read as a reader would: every page's blocks intact, usable from its files, nothing extra in it.

Builds the site once (``mkdocs build``, about 10 s) into a temporary folder and reads its HTML.
"""

from __future__ import annotations

import os
import re
import shutil
import subprocess
import sys
from pathlib import Path
from urllib.parse import unquote, urlsplit

import markdown
import pytest

from .site_html import page_problems
from .test_site import HOOKS, REPO

pytest.importorskip("material", reason="the docs extra: pip install -e '.[docs]'")


@pytest.fixture(scope="module")
def site(tmp_path_factory) -> Path:
    out = tmp_path_factory.mktemp("site")
    subprocess.run([sys.executable, "-m", "mkdocs", "build", "--strict", "--quiet", "--site-dir", str(out)],
                   cwd=REPO, check=True, capture_output=True, env={**os.environ, "NO_MKDOCS_2_WARNING": "1"})
    return out


def render(text: str) -> str:
    """``text`` through the site's math hooks and Markdown, as a page of the site is."""
    stash = HOOKS.MathStash(0)
    html_text = markdown.markdown(HOOKS.stash_math(text, stash), extensions=["tables", "md_in_html", "pymdownx.superfences"])
    return f"<article>{stash.restore(html_text)}</article>"


def test_an_equation_that_starts_a_line_stays_in_its_list_item_and_paragraph():
    page = ("1. Images of the walls, whose strength\n   $q_i$ falls with distance.\n"
            "2. Intrinsic dipoles.\n\nA field\n$E$ at\n$x$.\n\n- N-patch.\n")
    out = render(page)
    assert page_problems(out) == [], out
    assert out.count("<li>") == 3 and out.count("<math") == 3


def test_the_checker_sees_an_equation_outside_every_block_and_a_list_marker_in_text():
    broken = ("<article><ol><li><p>Images</p></li></ol>"
              '<math display="inline"><mi>q</mi></math><p>falls off.\n2. Intrinsic dipoles</p></article>')
    problems = page_problems(broken)
    assert len(problems) == 2 and "outside every paragraph" in problems[0] and "2. Intrinsic" in problems[1]


def test_the_checker_sees_latex_the_build_left_unconverted():
    assert page_problems(render("A skill of $1 - $ sse.\n")) != []  # a space before the closing $: not maths
    assert page_problems(render("$$\\hat\\mu = \\bar y$$\n")) != []  # $$ is not the site's display maths
    assert page_problems(render("A skill of $1 - s$ and\n\n```math\n\\hat\\mu\n```\n")) == []


def test_a_display_equation_becomes_a_block_inside_its_list_item():
    out = render("1. The field:\n\n    ```math\n    E = \\frac{q}{r^2}\n    ```\n\n2. Next.\n")
    assert re.search(r'<li>.*<div class="math"><math [^>]*display="block">.*</li>', out, re.S), out
    assert "<p><div" not in out and page_problems(out) == []


def test_every_page_of_the_site_reads_right(site):
    pages = sorted(site.rglob("*.html"))
    assert len(pages) > 30
    found = {str(p.relative_to(site)): page_problems(p.read_text()) for p in pages}
    assert not any(found.values()), {page: problems[:3] for page, problems in found.items() if problems}


def test_the_site_works_from_its_files(site):
    """Opened by ``file://``: links name pages, not folders (no server adds ``index.html``), and search is there."""
    folders = []
    for page in site.rglob("*.html"):
        for href in re.findall(r'href="([^"#?]+)', page.read_text()):
            if urlsplit(href).scheme or href.startswith("//"):
                continue
            if (page.parent / unquote(href)).resolve().is_dir():
                folders.append(f"{page.relative_to(site)} -> {href}")
    assert not folders, folders[:10]
    assert (site / "search" / "search_index.js").is_file()  # the offline plugin's index, read without a server


def test_no_page_loads_anything_from_the_network(site):
    """Scripts, styles and fonts all ship with the site: opened with no network, nothing is missing."""
    remote = re.compile(r'<(?:script|link)\b[^>]*(?:src|href)="(?:https?:)?//[^"]+"')
    found = {str(p.relative_to(site)): remote.findall(p.read_text()) for p in site.rglob("*.html")}
    assert not any(found.values()), {page: tags[:2] for page, tags in found.items() if tags}


CHROMIUM = shutil.which("chromium") or shutil.which("chromium-browser") or shutil.which("google-chrome")


@pytest.mark.skipif(CHROMIUM is None, reason="no Chromium to open the site in (.ci/run installs Debian's chromium)")
def test_search_finds_a_word_from_the_sites_files_in_a_real_browser(site):
    """Headless Chromium opens index.html?q=tolerance by file:// (no server, no network): the search index loads
    through the shipped worker shim and lists the pages that say "tolerance"."""
    dom = subprocess.run([CHROMIUM, "--headless", "--no-sandbox", "--disable-gpu", "--virtual-time-budget=10000",
                          "--dump-dom", (site / "index.html").as_uri() + "?q=tolerance"],
                         capture_output=True, text=True, timeout=120).stdout
    found = re.search(r'md-search-result__meta">(\d+) matching document', dom)
    assert found and int(found.group(1)) >= 1, "no search result: " + (
        "still initializing (the worker shim did not load)" if "Initializing search" in dom else dom[-300:])
    assert dom.count('class="md-search-result__item"') >= 1


MATH_FONT = "TeX Gyre Termes Math"
FONT_PROBE = """<!doctype html><html><head><link rel="stylesheet" href="../css/extra.css"></head><body>
<div class="md-typeset"><math><mrow><mo>{</mo><mfrac><mi>a</mi><mi>b</mi></mfrac></mrow></math></div>
<pre id="fonts">pending</pre><script>document.fonts.ready.then(() => {
  document.getElementById("fonts").textContent = [...document.fonts].map(f => f.family + "=" + f.status).join(";");
});</script></body></html>"""


def test_the_equations_maths_font_ships_with_the_site(site):
    """The stylesheet sets the maths font on every equation and its file (with its licence) is in the site."""
    css = (site / "css" / "extra.css").read_text()
    face = re.search(r'@font-face \{ font-family: "([^"]+)"; src: url\("([^"]+)"\)', css)
    assert face and face.group(1) == MATH_FONT
    assert (site / "css" / face.group(2)).resolve().is_file()
    assert re.search(rf'\.md-typeset math \{{ font-family: "{MATH_FONT}"', css)
    assert (site / "fonts" / "LICENSE-texgyretermes-math.txt").is_file()


@pytest.mark.skipif(CHROMIUM is None, reason="no Chromium to open the site in (.ci/run installs Debian's chromium)")
def test_a_real_browser_loads_the_maths_font_from_the_sites_files(site):
    """Opened by file:// with no network, a page of the site that holds an equation loads the shipped font (a
    browser's default fonts have no OpenType MATH table: braces would not stretch)."""
    probe = site / "model" / "font-probe.html"
    probe.write_text(FONT_PROBE)
    try:
        dom = subprocess.run([CHROMIUM, "--headless", "--no-sandbox", "--disable-gpu", "--virtual-time-budget=5000",
                              "--dump-dom", probe.as_uri()], capture_output=True, text=True, timeout=120).stdout
    finally:
        probe.unlink()
    fonts = re.search(r'id="fonts">([^<]*)<', dom)
    assert fonts and f"{MATH_FONT}=loaded" in fonts.group(1).split(";"), fonts.group(1) if fonts else dom[-300:]


def test_the_sites_build_code_is_not_in_the_site(site):
    assert not list(site.rglob("*.py"))
