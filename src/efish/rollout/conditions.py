"""``conditions.parquet``: what each condition of an assay resolved to in this run.

An assay composes its conditions once (:func:`efish.rollout.assay.condition_configs`, with the run's overrides)
and records them here beside its tables: the summary columns a reader filters on (policy, agents, sizes, roles,
arena, fps, bot, interventions) and the whole resolved config as JSON, which
:func:`efish.config.recorded.recorded_conditions` reads back. Panels, clips and claims use this record, so an
override of the run (``env.fps=...``, an assay's sizes) reaches every drawing.
"""

from __future__ import annotations

from collections.abc import Mapping

import pandas as pd

from ..config.recorded import config_json
from ..config.schema import EfishConfig


def conditions_table(configs: Mapping[str, EfishConfig]) -> pd.DataFrame:
    """One row per condition (in the assay's order) of :data:`efish.rollout.schema.CONDITION_COLUMNS`."""
    rows = []
    for position, (name, cfg) in enumerate(configs.items()):
        env, arena = cfg.env, cfg.arena
        rows.append({
            "condition": name, "position": position, "overrides": [str(o) for o in cfg.assay.conditions[name]],
            "policy": cfg.assay.policy, "episodes": min(cfg.assay.episodes, cfg.scale.max_episodes),
            "seed": cfg.assay.seed, "n_agents": env.n_agents, "sizes": [float(s) for s in env.sizes],
            "roles": [str(r) for r in env.roles], "muted": [int(i) for i in env.muted],
            "frozen": [int(i) for i in env.frozen], "bots": [int(i) for i in env.bots],
            "bot_eod_rate": env.bot_eod_rate, "arena_layout": arena.layout, "arena_width_cm": arena.width_cm,
            "arena_height_cm": arena.height_cm, "fps": env.fps, "episode_steps": env.episode_steps,
            "config": config_json(cfg),
        })
    return pd.DataFrame(rows)
