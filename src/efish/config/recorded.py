"""A config recorded beside an output, read back without composing: the run's own record, not the config files.

An assay writes each condition's resolved config into ``conditions.parquet``
(:func:`efish.rollout.conditions.conditions_table`) as :func:`config_json`;
panels and clips read it back here, so they draw what the run simulated, with
every override the run had, and never compose Hydra configs of their own.
JSON of the dataclass tree rather than OmegaConf YAML: reading a condition
back takes about a millisecond instead of most of a second.
"""

from __future__ import annotations

import dataclasses
import json
import typing
from collections.abc import Mapping
from functools import lru_cache

import pandas as pd

from .schema import ConfigError, EfishConfig, validate


def config_json(cfg: EfishConfig) -> str:
    """The resolved config as JSON (every group, every field): what :func:`from_json` reads back."""
    return json.dumps(dataclasses.asdict(cfg))


@lru_cache(maxsize=256)
def from_json(text: str) -> EfishConfig:
    """The validated :class:`EfishConfig` that :func:`config_json` wrote. Cached: panels read the same conditions
    many times; treat the result as read-only."""
    try:
        data = json.loads(text)
    except json.JSONDecodeError as exc:
        raise ConfigError(f"a recorded config is not JSON: {exc}") from None
    cfg = _build(EfishConfig, data, "")
    validate(cfg)
    return cfg


def _build(cls: type, data: object, path: str):
    """Dataclass ``cls`` from its ``asdict`` form; a key the schema lacks is one ConfigError naming it."""
    if not isinstance(data, dict):
        raise ConfigError(f"recorded config {path or 'root'}: expected a mapping, got {type(data).__name__}")
    hints = typing.get_type_hints(cls)
    names = {f.name for f in dataclasses.fields(cls)}
    if unknown := sorted(set(data) - names):
        raise ConfigError(f"recorded config {path}{unknown[0]}: not a key of this efish version's schema")
    values = {k: _build(hints[k], v, f"{path}{k}.") if dataclasses.is_dataclass(hints[k]) else v
              for k, v in data.items()}
    return cls(**values)


def recorded_conditions(conditions: pd.DataFrame, what: str = "the conditions table") -> Mapping[str, EfishConfig]:
    """Condition -> its config as the run resolved it, in the assay's order (the first is the control), from a
    ``conditions.parquet`` table (its ``condition``, ``position`` and ``config`` columns)."""
    missing = [c for c in ("condition", "position", "config") if c not in conditions.columns]
    if missing:
        raise ValueError(f"{what} lacks columns {missing}: rerun the assay (efish assay writes conditions.parquet)")
    rows = conditions.sort_values("position")
    return {str(c): from_json(text) for c, text in zip(rows["condition"], rows["config"], strict=True)}
