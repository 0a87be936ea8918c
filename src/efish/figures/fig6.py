"""Fig 6: hidden-state dynamics: dimensionality, decoding, PLSC between agents and wideband power (SPEC 13)."""

from __future__ import annotations

from .panel import Panel

PANELS: list[Panel] = []
