"""What a panel is: its figure and id, the function that draws it, the tables it reads and its caption.

Each figure module (``fig1`` ... ``fig6``, ``supplement``) ends with a list
``PANELS`` of these; :mod:`efish.figures.registry` gathers them. A panel
draws on one matplotlib axes (``projection`` picks e.g. a polar one) from a
dict of tables keyed like its ``inputs``; a schematic panel reads nothing
(``inputs={}``).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field

import pandas as pd

Tables = dict[str, pd.DataFrame]


@dataclass(frozen=True)
class Panel:
    """One panel. ``inputs`` maps a table name to a path relative to ``results/{run}``; a path with ``{seed}``
    stands for every trained seed (concatenated with a ``seed`` column). ``caption`` says what the panel
    shows, from which assay, table and statistic (it is the report's caption)."""

    figure: str
    name: str
    draw: Callable[[Tables, object], None]
    inputs: dict[str, str] = field(default_factory=dict)
    caption: str = ""
    projection: str | None = None

    @property
    def key(self) -> str:
        return f"{self.figure}/{self.name}"

    def assays(self) -> set[str]:
        """Assays whose tables this panel reads (rollout or analysis tables)."""
        names = set()
        for path in self.inputs.values():
            parts = path.split("/")
            if parts[0] == "assays":
                names.add(parts[1])
            elif parts[0] == "analysis" and len(parts) > 3:  # analysis/<analysis>/<assay>/<table>.parquet
                names.add(parts[2])
        return names

    def top_seed_assays(self) -> set[str]:
        """Assays of the top-ranked seeds whose stacked tables this panel reads (``seeds/<assay>/...``)."""
        return {path.split("/")[1] for path in self.inputs.values() if path.startswith("seeds/")}
