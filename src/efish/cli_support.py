"""What every ``efish`` command shares: the run a command's overrides name, the record beside its outputs, and
how its ``--help`` is written (one wording for the overrides, one form for a documentation page)."""

from __future__ import annotations

import argparse
import textwrap
from collections.abc import Sequence
from pathlib import Path

from .config import run_name, to_yaml
from .layout import Run


def write_metadata(folder: Path, cfg, started, args, name: str = "provenance.json", **extra) -> None:
    """config.yaml and provenance (with the command's overrides) beside an output."""
    from .io import write_run_metadata

    write_run_metadata(folder, to_yaml(cfg), started, {"overrides": list(args.overrides), **extra}, name=name)


def run_of(cfg, overrides: Sequence[str]) -> Run:
    """The run the scale and ``overrides`` name: the folders of a command's default outputs (:mod:`efish.layout`)."""
    return Run(run_name(cfg.scale.name, [o for o in overrides if not o.startswith("scale=")]))


def run_at(where: str | Path, results_root: Path = Path("results")) -> Run:
    """The run ``where`` names on a command line: its folder name under ``results_root`` (smoke, laptop-453280a3),
    or its folder as the README's table spells it (results/laptop)."""
    where = Path(where)
    return Run(where.name, results_root=where.parent) if len(where.parts) > 1 else Run(str(where),
                                                                                       results_root=results_root)


# ------------------------------------------------------------------ help text

# The documentation pages the command line cites, each by its place in the site's navigation (mkdocs.yml's nav;
# tests/test_cli_help.py checks that the two agree). Help names a page by this title and its path in docs/, the
# form docs/hooks.py turns into a link on the site's command-line reference.
DOC_PAGES: dict[str, str] = {
    "docs/getting-started.md": "Getting started",
    "docs/tutorials/override-configs.md": "Tutorials › Override configs",
    "docs/tutorials/add-an-analysis.md": "Tutorials › Add an analysis",
    "docs/tutorials/read-the-tables.md": "Tutorials › Read the tables",
    "docs/tutorials/render-an-episode.md": "Tutorials › Render an episode",
    "docs/tutorials/compare-claims.md": "Tutorials › Compare two runs' claims",
    "docs/tutorials/watch-a-run.md": "Tutorials › Watch a run train",
    "docs/tutorials/sweep-a-parameter.md": "Tutorials › Sweep a parameter",
    "docs/model/effect-plan.md": "The model › The effect plan",
    "docs/model/accuracy.md": "The model › Accuracy and stability",
    "docs/methods/training.md": "Methods › Training",
    "docs/methods/assays.md": "Methods › Assays",
    "docs/methods/analyses.md": "Methods › Analyses",
    "docs/methods/figures.md": "Methods › Figures",
    "docs/claims/index.md": "Claims › Rules and claims",
    "docs/claims/results.md": "Claims › Results",
    "docs/claims/along-training.md": "Claims › Along training",
    "docs/claims/power.md": "Claims › What a verdict costs",
    "docs/benchmarks.md": "Benchmarks",
    "docs/reference/config.md": "Reference › Configuration",
    "docs/reference/tables.md": "Reference › Tables",
    "docs/reference/cli.md": "Reference › Command line",
}


def doc_page(path: str) -> str:
    """A documentation page as help names it, ``Claims › Rules and claims (docs/claims/index.md#rule-4)``, from its
    path in the repository (an anchor allowed); a page missing from :data:`DOC_PAGES` is an error."""
    page = path.partition("#")[0]
    if page not in DOC_PAGES:
        raise KeyError(f"{page} is not in efish.cli_support.DOC_PAGES: add it with its title in mkdocs.yml's nav")
    return f"{DOC_PAGES[page]} ({path})"


def see_docs(*paths: str) -> str:
    """The paragraph of a command's help that says which pages to read: ``docs: <page>``, one page per line."""
    return "docs: " + "\n      ".join(doc_page(path) for path in paths)


def _has_indented_line(paragraph: str) -> bool:
    """Whether a paragraph of help is laid out by hand (a list of examples: its lines after the first indented)."""
    return any(line.startswith(" ") for line in paragraph.splitlines())


class HelpFormatter(argparse.HelpFormatter):
    """argparse's formatter, except that a description or epilog keeps its paragraphs (blank-line separated, each
    wrapped on its own), a paragraph with indented lines is kept as written (examples), and no line breaks inside a word
    (a path like docs/tutorials/override-configs.md stays whole, so it can be read, copied and linked)."""

    def _fill_text(self, text: str, width: int, indent: str) -> str:
        paragraphs = textwrap.dedent(text).strip("\n").split("\n\n")
        return "\n\n".join(textwrap.indent(p, indent) if _has_indented_line(p) else self._fill(p, width, indent)
                             for p in paragraphs)

    def _fill(self, paragraph: str, width: int, indent: str) -> str:
        return textwrap.fill(" ".join(paragraph.split()), width, initial_indent=indent, subsequent_indent=indent,
                             break_on_hyphens=False, break_long_words=False)

    def _split_lines(self, text: str, width: int) -> list[str]:
        return textwrap.wrap(" ".join(text.split()), width, break_on_hyphens=False, break_long_words=False)


def add_command(sub: argparse._SubParsersAction, name: str, summary: str, description: str,
                *docs: str) -> argparse.ArgumentParser:
    """A subcommand: ``summary`` is its line in the parent's list, ``description`` opens its ``--help`` (what it
    does and writes), followed by the pages of the documentation to read (``docs``, paths under docs/)."""
    text = f"{description}\n\n{see_docs(*docs)}" if docs else description
    return sub.add_parser(name, help=summary, description=text, formatter_class=HelpFormatter)


OVERRIDES_EXAMPLE = "physics.image_order=2 arena=patchy70"


def add_overrides(parser: argparse.ArgumentParser, example: str = OVERRIDES_EXAMPLE, note: str = "",
                  run: bool = False) -> None:
    """The positional ``overrides`` of a command that composes the config, with one wording everywhere: Hydra's
    ``key=value`` or a config group's choice, an example for this command (``example``) and what else it reads
    there (``note``). ``run``: a command that reads a finished run also takes the run there, as its folder
    (results/laptop) or its name (:func:`run_at`): one word that is no override (:class:`_RunAndOverrides`), kept
    in ``args.run`` (None without it); its ``note`` says so."""
    text = (f"Hydra overrides of the config: key=value or a config group's choice, e.g. {example}"
            f"{f'; {note}' if note else ''} (efish config lists the keys)")
    if run:
        parser.set_defaults(run=None)
    parser.add_argument("overrides", nargs="*", help=text, **({"action": _RunAndOverrides} if run else {}))


class _RunAndOverrides(argparse.Action):
    """Positional words of a command that reads a finished run: one that is no Hydra override (no ``=``, no leading
    ``+`` or ``~``) names the run (``args.run``), the others stay overrides; a second run is a usage error."""

    def __call__(self, parser, namespace, values, option_string=None) -> None:
        runs = [v for v in values if "=" not in v and not v.startswith(("+", "~"))]
        if len(runs) > 1:
            parser.error(f"one run at a time, not {', '.join(runs)}")
        namespace.run = runs[0] if runs else None
        setattr(namespace, self.dest, [v for v in values if v not in runs])
