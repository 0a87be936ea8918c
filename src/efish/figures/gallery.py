"""The gallery of a run: every registered panel as the run drew it, web-sized, with its caption, on one page.

``efish gallery laptop`` reads ``figures/laptop/<figure>/<panel>.png`` and the run's provenance and writes
``docs/gallery/index.md`` and ``docs/gallery/img/<figure>/<panel>.png`` (docs/methods/figures.md#gallery).
The page lists every panel of :data:`efish.figures.registry.PANELS`, grouped by figure, each with its caption; a
panel without a PNG in the run keeps its place and says why it is absent where the run's config tells (its
scale runs none of the panel's assays). Other drawings of the run (the benchmarks' figures) follow. The header
names the run, the commits its panels were drawn and its tables computed at, and the CPU and torch's CPU
capability that ``efish bench physics`` recorded; a fact the run did not record is said to be missing, never
guessed. Copies are at most :data:`MAX_WIDTH_PX` wide with a 256-colour palette, so the gallery of the 79
panels stays under 2 MB.
"""

from __future__ import annotations

import html
import importlib
import json
import re
from collections import Counter
from collections.abc import Iterable
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING

from ..io import atomic_path, write_text_atomic
from ..layout import BENCH, FIGURES_ROOT, RESULTS_ROOT

if TYPE_CHECKING:  # the command line imports this module for its defaults: nothing heavy at import
    from .panel import Panel

#: The site's gallery (docs/gallery/index.md), which the developers regenerate with ``--out docs/gallery``.
SITE_GALLERY = Path("docs/gallery")
#: The folder of a run's own gallery, under its figure folder: ``efish gallery``'s default, so that a user's run
#: never overwrites the site's page.
GALLERY = "gallery"
PAGE = "index.md"
IMAGES = "img"
MAX_WIDTH_PX = 900
COLOURS = 256
NOT_DRAWN = "not drawn in this run"
OTHERS = "## Other drawings of the run {#other-drawings}"  # the heading after the registry's panels
#: Where ``efish bench physics --out results/<run>/bench`` records the CPU and torch's CPU capability.
BENCH_PHYSICS = f"{BENCH}/bench_physics.json"
#: The figure module whose docstring describes each figure of the registry (``fig1`` ... ``fig6``, ``supp``).
FIGURE_MODULES = {"supp": "supplement"}
FIGURE_TITLES = {"supp": "Supplement"}
_DOCS_REFERENCE = re.compile(r",?\s*\(?docs/[\w/.#-]+\)?")
_MARKDOWN = re.compile(r"([\\`*_\[\]])")
#: A caption's reference to a page of the site, ``docs/<page>.md#<anchor>``: a link on the page (the gallery is one
#: folder below docs/, as the site's hooks link the generated pages' references).
_DOCS_LINK = re.compile(r"\bdocs/(?P<page>[\w/-]+\.md)(?P<anchor>#[\w-]+)?")


def markdown_text(text: str, links: bool = False) -> str:
    """``text`` as Markdown that renders as written: HTML and emphasis characters escaped, ``$`` (the site's
    inline math) as an entity; with ``links``, its ``docs/<page>.md#<anchor>`` references as links."""
    def plain(part: str) -> str:
        return _MARKDOWN.sub(r"\\\1", html.escape(part, quote=False)).replace("$", "&#36;")

    if not links:
        return plain(text)
    out, last = [], 0
    for m in _DOCS_LINK.finditer(text):
        label = plain(m["page"].removesuffix(".md"))
        out += [plain(text[last:m.start()]), f"[{label}](../{m['page']}{m['anchor'] or ''})"]
        last = m.end()
    return "".join([*out, plain(text[last:])])


def web_png(source: Path, target: Path, max_width: int = MAX_WIDTH_PX) -> tuple[int, int]:
    """``source`` on white, at most ``max_width`` pixels wide, in a dithered 256-colour palette, written to
    ``target`` (atomically); returns its (width, height). The same PNG always gives the same bytes."""
    from PIL import Image

    with Image.open(source) as im:
        rgba = im.convert("RGBA")
    rgb = Image.alpha_composite(Image.new("RGBA", rgba.size, "white"), rgba).convert("RGB")
    if rgb.width > max_width:
        rgb = rgb.resize((max_width, max(1, round(rgb.height * max_width / rgb.width))), Image.Resampling.LANCZOS)
    palette = rgb.quantize(colors=COLOURS, method=Image.Quantize.FASTOCTREE)
    small = rgb.quantize(palette=palette, dither=Image.Dither.FLOYDSTEINBERG)
    with atomic_path(target) as tmp:
        small.save(tmp, format="PNG", optimize=True)
    return small.size


def _json(path: Path) -> dict | None:
    try:
        return json.loads(path.read_text())
    except (OSError, ValueError):
        return None


@dataclass
class Source:
    """What the run recorded: each drawing's provenance, the tables' commits, the CPU and the scale."""

    figures: Path
    results: Path
    provenance: dict[str, dict] = field(default_factory=dict)  # drawing key (fig3/M, bench/bench_accuracy) -> it
    table_commits: Counter = field(default_factory=Counter)
    cpu: dict | None = None
    scale: dict | None = None

    @classmethod
    def read(cls, figures: Path, results: Path) -> Source:
        import yaml

        source = cls(Path(figures), Path(results))
        for png in sorted(source.figures.glob("*/*.png")):
            record = _json(png.with_suffix(".provenance.json"))
            source.provenance[f"{png.parent.name}/{png.stem}"] = record or {}
        for path in sorted(source.results.rglob("*provenance.json")):
            if (record := _json(path)) is not None:
                source.table_commits[record.get("git_commit")] += 1
        source.cpu = _json(source.results / BENCH_PHYSICS)
        try:
            source.scale = (yaml.safe_load((source.figures / "config.yaml").read_text()) or {}).get("scale")
        except (OSError, yaml.YAMLError, AttributeError):
            source.scale = None
        return source

    def why_absent(self, panel: Panel) -> str:
        """Why ``panel`` has no PNG, as far as the run's recorded scale tells."""
        if not self.scale:
            return "the run has no PNG of it (and no config.yaml beside its figures to tell why)"
        missing = sorted(panel.assays() - set(self.scale.get("assays") or ()))
        top = set(self.scale.get("top_seed_assays") or ()) if self.scale.get("top_seeds") else set()
        missing_top = sorted(panel.top_seed_assays() - top)
        name = self.scale.get("name", "?")
        if missing:
            return f"scale {name} runs no {', '.join(missing)} assay"
        if missing_top:
            return f"scale {name} reruns no top seeds on {', '.join(missing_top)}"
        return f"the run has no PNG of it, though scale {name} draws it: its figure job has not run, or the run " \
               "predates the panel"


def _commits(counts: Counter, unit: str) -> str:
    if not counts:
        return "not recorded"
    return ", ".join(f"`{(c or 'unknown')[:7]}` ({n} {unit}{'s' if n != 1 else ''})" for c, n in counts.most_common())


def header(run: str, source: Source, drawn: list[str], registered: int, command: str) -> list[str]:
    """The page's title, how to regenerate it and what the run recorded about itself."""
    records = [source.provenance[k] for k in drawn]
    panel_commits = Counter(r.get("git_commit") for r in records)
    times = sorted(t for r in records for t in (r.get("started"), r.get("finished")) if t)
    if not times:
        when = "at a time not recorded"
    else:
        first, last = times[0][:16].split("T"), times[-1][:16].split("T")
        when = f"{first[0]} {first[1]} to {'' if last[0] == first[0] else last[0] + ' '}{last[1]} UTC"
    software = Counter(
        (r.get("efish_version"), r.get("python"), (r.get("packages") or {}).get("torch"), r.get("platform"))
        for r in records).most_common(1)
    if source.cpu and source.cpu.get("cpu"):
        cpu = (f"{source.cpu['cpu']}; torch CPU capability {source.cpu.get('cpu_capability', 'not recorded')} "
               f"(`{source.results / BENCH_PHYSICS}`)")
    else:
        cpu = f"not recorded (no `{source.results / BENCH_PHYSICS}`)"
    lines = [
        f"# Gallery: the {run} run",
        "",
        f"<!-- Generated by `{command}`: rerun it after a run rather than editing this page. -->",
        "",
        f"Every panel of the paper's figures as the run `{run}` drew it, each with the caption the figure registry "
        "gives it (what the panel shows, from which assay, table and statistic; [Figures](../methods/figures.md#panels) "
        "says how panels are drawn). The images are web-sized copies; the run's own PNG and PDF are "
        f"`{source.figures}/<figure>/<panel>.png|pdf`. Regenerate this page and its images from a run with",
        "",
        "```bash",
        command,
        "```",
        "",
        f"- **Run**: `{run}`"
        + (f" (scale `{source.scale.get('name')}`)" if source.scale and source.scale.get("name") else ""),
        f"- **Panels drawn**: {len(drawn)} of the {registered} registered, {when}",
        f"- **Panels drawn at commit**: {_commits(panel_commits, 'panel')}",
        f"- **Tables computed at commit**: {_commits(source.table_commits, 'output')}",
        f"- **CPU**: {cpu}",
    ]
    if software:
        (efish, python, torch, platform), _ = software[0]
        lines.append(f"- **Software**: efish {efish}, Python {python}, torch {torch}; {platform}")
    return [*lines, ""]


def figure_intro(figure: str) -> str:
    """The first paragraph of the figure's module docstring, without its references to the docs' sources."""
    module = importlib.import_module(f"efish.figures.{FIGURE_MODULES.get(figure, figure)}")
    first = " ".join((module.__doc__ or "").split("\n\n")[0].split())
    first = re.sub(r"^Fig \d+: ", "", _DOCS_REFERENCE.sub("", first).strip())
    return markdown_text(first[:1].upper() + first[1:])


def _figure_order(figure: str) -> tuple:
    """Figures 1-6 in number order, then the others (the supplement) by name."""
    number = re.fullmatch(r"fig(\d+)", figure)
    return (0, int(number[1]), "") if number else (1, 0, figure)


def figure_title(figure: str) -> str:
    return FIGURE_TITLES.get(figure, re.sub(r"^fig(\d+)$", r"Figure \1", figure))


def entry(key: str, image: str | None, caption: str, absent: str = "") -> list[str]:
    """One panel (or other drawing) of the grid, all Markdown: its image linked to itself, or ``absent`` (why it
    is not drawn) in its place; then its id and caption."""
    picture = (f"[![{key}]({image}){{ loading=lazy }}]({image})" if image
               else f'<div class="efish-gallery-missing" markdown>{absent}</div>')
    return [f'<figure markdown id="{key.replace("/", "-")}">', "", picture, "", "<figcaption markdown>", "",
            f"**{key}**: {caption}", "", "</figcaption>", "</figure>", ""]


def _grid(entries: Iterable[list[str]]) -> list[str]:
    return ['<div class="efish-gallery" markdown>', "", *[line for e in entries for line in e], "</div>", ""]


def gallery_folder(run: str, figures: Path | None = None, out: Path | None = None) -> Path:
    """Where a run's gallery goes: ``out``, else ``<figures>/gallery`` (``figures`` defaulting to ``figures/<run>``)."""
    return Path(out) if out is not None else (Path(figures) if figures is not None else FIGURES_ROOT / run) / GALLERY


def write_gallery(run: str, figures: Path | None = None, results: Path | None = None, out: Path | None = None,
                  max_width: int = MAX_WIDTH_PX, command: str | None = None) -> tuple[int, int]:
    """Write ``out/index.md`` and ``out/img/`` for the run ``run`` (its folders default to ``figures/<run>`` and
    ``results/<run>``, ``out`` to ``<figures>/gallery``); images of an earlier gallery that this run does not draw
    are removed. ``command`` is the line the page says regenerates it. Returns (registered panels drawn, registered
    panels not drawn)."""
    from .registry import PANELS
    from .registry import figures as by_figure

    figures = Path(figures) if figures is not None else FIGURES_ROOT / run
    results = Path(results) if results is not None else RESULTS_ROOT / run
    out = gallery_folder(run, figures, out)
    if not figures.is_dir():
        raise ValueError(f"no figure folder {figures}: draw the run's figures first, or pass --figures")
    if max_width < 16:
        raise ValueError(f"--max-width must be at least 16 pixels, got {max_width}")
    source = Source.read(figures, results)
    written: set[Path] = set()

    def copy(key: str) -> str:
        relative = f"{IMAGES}/{key}.png"
        web_png(figures / f"{key}.png", out / relative, max_width)
        written.add(out / relative)
        return relative

    drawn = [k for k in PANELS if k in source.provenance]
    lines = header(run, source, drawn, len(PANELS), command or f"efish gallery {run}")
    for figure, panels in sorted(by_figure().items(), key=lambda item: _figure_order(item[0])):
        lines += [f"## {figure_title(figure)} {{#{figure}}}", "", figure_intro(figure), ""]
        lines += _grid(entry(p.key, copy(p.key), markdown_text(p.caption, links=True)) if p.key in source.provenance
                       else entry(p.key, None, markdown_text(p.caption, links=True),
                                  f"{NOT_DRAWN}: {markdown_text(source.why_absent(p))}") for p in panels)
    others = [k for k in source.provenance if k not in PANELS]
    if others:
        lines += [OTHERS, "", "Drawings in the run's figure folder that are not panels of the figure registry, with "
                  "the command that drew each.", ""]
        lines += _grid(entry(k, copy(k), _made_by(source.provenance[k])) for k in others)
    write_text_atomic(out / PAGE, "\n".join(lines).rstrip("\n") + "\n")
    for stale in sorted((out / IMAGES).rglob("*.png")):
        if stale not in written:
            stale.unlink()
    return len(drawn), len(PANELS) - len(drawn)


def _made_by(record: dict) -> str:
    command = record.get("command") or []
    if not command:
        return "drawn by a command the run did not record"
    return f"drawn by `{' '.join(['efish', *command[1:]])}`"
