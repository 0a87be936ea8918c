"""A config recorded beside an output, read back without composing: the run's own record, not the config files.

An assay writes each condition's resolved config into ``conditions.parquet``
(:func:`efish.rollout.conditions.conditions_table`) as :func:`config_json`;
analyses, claims, panels and clips read it back here (:func:`recorded_conditions`), so they use what the run
simulated (its frame rate, arena, roles), with every override the run had, and never compose Hydra configs of
their own. An analysis job records the analysis settings it ran with beside its tables in the same way
(:func:`settings_table`, ``analysis/<analysis>/<assay>/analysis_settings.parquet``), and panels that name a
threshold read them back (:func:`recorded_settings`): the thresholds the tables were computed under.
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

from .schema import AnalysisConfig, ConfigError, EfishConfig, validate

#: The column of an analysis settings table (:func:`settings_table`) that holds the settings as JSON.
SETTINGS_COLUMN = "settings"


def config_json(cfg: EfishConfig | AnalysisConfig) -> str:
    """A resolved config (the whole tree, or one group such as the analysis settings) as JSON, every field: what
    :func:`from_json` (or :func:`recorded_settings`) reads back."""
    return json.dumps(dataclasses.asdict(cfg))


def from_json(text: str) -> EfishConfig:
    """The validated :class:`EfishConfig` that :func:`config_json` wrote. Cached: panels read the same conditions
    many times; treat the result as read-only."""
    return _read(EfishConfig, text, "")


@lru_cache(maxsize=256)
def _read(cls: type, text: str, path: str):
    """The validated ``cls`` (keys under ``path``) that :func:`config_json` wrote as ``text``."""
    try:
        data = json.loads(text)
    except json.JSONDecodeError as exc:
        raise ConfigError(f"a recorded config is not JSON: {exc}") from None
    cfg = _build(cls, data, path)
    validate(cfg, path)
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


def step_rates(configs: Mapping[str, EfishConfig]) -> dict[str, float]:
    """Condition -> the steps per second (``env.fps``) the run simulated it at, from :func:`recorded_conditions`:
    the factor from an EOD probability per step to a rate in Hz, and 1000 / it the ms of one step."""
    return {c: float(cfg.env.fps) for c, cfg in configs.items()}


def settings_table(settings: AnalysisConfig) -> pd.DataFrame:
    """The analysis settings an analysis job ran with, as the one-row table it writes beside its tables
    (``analysis_settings.parquet``: the settings as JSON in :data:`SETTINGS_COLUMN`)."""
    return pd.DataFrame({SETTINGS_COLUMN: [config_json(settings)]})


def recorded_settings(table: pd.DataFrame, what: str = "the analysis settings table") -> AnalysisConfig:
    """The analysis settings (``cfg.analysis``) an analysis job recorded in :func:`settings_table`: the thresholds
    its tables were computed under, which a panel names."""
    if SETTINGS_COLUMN not in table.columns or len(table) != 1:
        raise ValueError(f"{what} is not one row with a {SETTINGS_COLUMN!r} column: rerun the analysis (efish "
                         "analyze records the settings it ran with)")
    return _read(AnalysisConfig, str(table[SETTINGS_COLUMN].iloc[0]), "analysis.")
