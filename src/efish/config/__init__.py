"""Typed, validated configuration composed with Hydra."""

from .compose import compose, config_dir, run_name, to_yaml
from .schema import (
    ConfigError,
    EfishConfig,
    PhysicsConfig,
    SensorsConfig,
    validate,
)

__all__ = [
    "ConfigError",
    "EfishConfig",
    "PhysicsConfig",
    "SensorsConfig",
    "compose",
    "config_dir",
    "run_name",
    "to_yaml",
    "validate",
]
