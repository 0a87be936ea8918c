"""Fig 4: ablations of receptor classes, collective sensing gates, muting, food layouts and patch number (SPEC 13)."""

from __future__ import annotations

from .panel import Panel

PANELS: list[Panel] = []
