"""Fig 5: the one-patch intruder assay, the bot, chasing and biting by size (SPEC 13)."""

from __future__ import annotations

from .panel import Panel

PANELS: list[Panel] = []
