"""``run_assay``: every condition of an assay config, one table set (SPEC 11)."""

from __future__ import annotations

from typing import Sequence

import pandas as pd

from ..config import compose
from .run import run_episodes


def run_assay(overrides: Sequence[str], policy) -> dict[str, pd.DataFrame]:
    """Compose the assay's config with ``overrides``, run each condition (its own overrides on top)
    for ``min(assay.episodes, scale.max_episodes)`` episodes, and return the concatenated ``steps``,
    ``episodes``, ``food`` tables."""
    base = compose(list(overrides))
    parts = []
    for name, extra in base.assay.conditions.items():
        cfg = compose(list(overrides) + list(extra))
        episodes = min(cfg.assay.episodes, cfg.scale.max_episodes)
        parts.append(run_episodes(cfg, policy, episodes, condition=name, seed=cfg.assay.seed,
                                  deterministic=cfg.assay.deterministic))
    return {k: pd.concat([p[k] for p in parts], ignore_index=True) for k in parts[0]}
