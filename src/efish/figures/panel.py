"""What a panel is: its figure and id, the function that draws it, the tables it reads and its caption.

Each figure module (``fig1`` ... ``fig6``, ``supplement``) ends with a list
``PANELS`` of these; :mod:`efish.figures.registry` gathers them. A panel
draws on one matplotlib axes (``projection`` picks e.g. a polar one) from a
dict of tables keyed like its :attr:`Panel.tables`: its ``inputs``; for
every assay it reads, that assay's ``conditions.parquet`` under
``conditions/<assay>`` (what each condition resolved to in the run: roles,
sizes, arena, fps); and for every analysis table it reads, the settings that
analysis job ran with (``analysis_settings.parquet``) under
``settings/<analysis>/<assay>`` (the thresholds the table was computed under),
so that a panel draws what the run simulated and analysed and never composes
a config of its own. A schematic panel reads nothing (``inputs={}``).
"""

from __future__ import annotations

import re
from collections.abc import Callable
from dataclasses import dataclass, field

import pandas as pd

from .. import layout

Tables = dict[str, pd.DataFrame]


def conditions_key(assay: str) -> str:
    """The key under which a panel's tables hold the conditions table of ``assay``: ``conditions/<assay>``."""
    return f"conditions/{assay}"


def settings_key(analysis: str, assay: str) -> str:
    """The key under which a panel's tables hold the settings analysis ``analysis`` of ``assay`` ran with:
    ``settings/<analysis>/<assay>``."""
    return f"settings/{analysis}/{assay}"


#: Characters that start inline markup in reStructuredText (``|E|`` would be a substitution reference, ``*x*``
#: emphasis, ``name_`` a link) and the backslash that escapes them.
_RST_MARKUP = re.compile(r"([\\`*_|])")


def rst_text(text: str) -> str:
    """``text`` escaped for reStructuredText, so that it renders as written: Snakemake's report reads captions as
    reST, where a plain ``|E|`` is an undefined substitution and the caption loses it."""
    return _RST_MARKUP.sub(r"\\\1", text)


@dataclass(frozen=True)
class Panel:
    """One panel. ``inputs`` maps a table name to a path relative to ``results/{run}`` (built with
    :mod:`efish.layout`); a path with ``{seed}`` stands for every trained seed (concatenated with a ``seed``
    column). A panel that needs an assay's conditions without reading another table of it names
    ``conditions/<assay>`` in ``inputs`` itself. ``caption`` says what the panel shows, from which assay, table
    and statistic (it is the report's caption)."""

    figure: str
    name: str
    draw: Callable[[Tables, object], None]
    inputs: dict[str, str] = field(default_factory=dict)
    caption: str = ""
    projection: str | None = None

    @property
    def key(self) -> str:
        return f"{self.figure}/{self.name}"

    @property
    def report_caption(self) -> str:
        """The caption as the report's reST text (:func:`rst_text`): it renders exactly as :attr:`caption` reads."""
        return rst_text(self.caption)

    def _parsed(self, kind: str) -> set[str]:
        return {t.assay for path in self.inputs.values() if (t := layout.parse_table(path)) and t.kind == kind}

    def assays(self) -> set[str]:
        """Assays whose tables this panel reads (rollout or analysis tables)."""
        return self._parsed("assays") | self._parsed("analysis")

    def top_seed_assays(self) -> set[str]:
        """Assays of the top-ranked seeds whose stacked tables this panel reads (``seeds/<assay>/...``)."""
        return self._parsed("seeds")

    @property
    def conditions(self) -> dict[str, str]:
        """The conditions table of every assay this panel reads: ``conditions/<assay>`` -> its path."""
        return {conditions_key(assay): layout.assay_table(assay, "conditions") for assay in sorted(self.assays())}

    @property
    def settings(self) -> dict[str, str]:
        """The settings of every analysis job whose tables this panel reads: ``settings/<analysis>/<assay>`` -> its
        ``analysis_settings.parquet``."""
        jobs = {(t.analysis, t.assay) for path in self.inputs.values()
                if (t := layout.parse_table(path)) and t.kind == "analysis"}
        return {settings_key(*job): layout.analysis_settings(*job) for job in sorted(jobs)}

    @property
    def tables(self) -> dict[str, str]:
        """Every table the panel reads, name -> relative path: its ``inputs``, then :attr:`conditions` and
        :attr:`settings`."""
        return {**self.inputs, **self.conditions, **self.settings}
