"""Fig 1: the model: training loop and sensing schematics, food layouts, fields of EODs distorted by objects and walls, sensor layout, a scene and its EOD raster (SPEC 13)."""

from __future__ import annotations

from .panel import Panel

PANELS: list[Panel] = []
