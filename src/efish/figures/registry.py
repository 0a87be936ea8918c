"""Every panel the pipeline draws, with the tables it reads (paths relative to ``results/{scale}``).

The workflow reads :data:`PANELS` to make one job per panel and one page per
figure; adding a panel means writing its function and one entry here. A path
with ``{seed}`` stands for every trained seed of the scale; its tables are
concatenated with a ``seed`` column.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Callable

from . import fig2, fig3, supplement


@dataclass(frozen=True)
class Panel:
    """One panel: figure id, panel id, the drawing function, its input tables and a caption."""

    figure: str
    name: str
    draw: Callable
    inputs: dict[str, str]
    caption: str

    @property
    def key(self) -> str:
        return f"{self.figure}/{self.name}"

    def assays(self) -> set[str]:
        """Assays whose tables this panel reads."""
        return {path.split("/")[1] for path in self.inputs.values() if path.startswith("assays/")}


PANELS: dict[str, Panel] = {p.key: p for p in [
    Panel("fig2", "B", fig2.trajectories, {"steps": "assays/homing/steps.parquet"},
          "Homing trajectories of the homing policy towards a frozen, always-emitting target (SPEC 11)."),
    Panel("fig3", "M", fig3.food_vs_size, {"episodes": "assays/patchy4/episodes.parquet"},
          "Food eaten per agent-episode against body size, selected seed, 4-agent patchy 70x70 arena."),
    Panel("supp", "training_curves", supplement.training_curves,
          {"metrics": "train/seed_{seed}/metrics.parquet", "ranking": "analysis/selection/ranking.parquet"},
          "Mean episode return during training, every seed; the selected seed in colour."),
    Panel("supp", "seed_landscape", supplement.seed_landscape, {"ranking": "analysis/selection/ranking.parquet"},
          "Seed selection (SPEC 10): food per episode against the size-food slope; marker area is R^2, "
          "hollow markers are seeds dropped for a non-positive intercept, the ring marks the selected seed."),
]}


def figures() -> dict[str, list[Panel]]:
    """Panels grouped by figure, in registry order."""
    grouped: dict[str, list[Panel]] = {}
    for panel in PANELS.values():
        grouped.setdefault(panel.figure, []).append(panel)
    return grouped


def panels_for(assays: list[str]) -> list[Panel]:
    """The panels whose assays are all among ``assays`` (what a scale can draw)."""
    return [p for p in PANELS.values() if p.assays() <= set(assays)]
