"""What every ``efish`` command shares: the run a command's overrides name, and the record beside its outputs."""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path

from .config import run_name, to_yaml
from .layout import Run


def write_metadata(folder: Path, cfg, started, args, name: str = "provenance.json", **extra) -> None:
    """config.yaml and provenance (with the command's overrides) beside an output."""
    from .io import write_run_metadata

    write_run_metadata(folder, to_yaml(cfg), started, {"overrides": list(args.overrides), **extra}, name=name)


def run_of(cfg, overrides: Sequence[str]) -> Run:
    """The run the scale and ``overrides`` name: the folders of a command's default outputs (:mod:`efish.layout`)."""
    return Run(run_name(cfg.scale.name, [o for o in overrides if not o.startswith("scale=")]))
