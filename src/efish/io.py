"""Atomic writes and provenance for every output folder (DESIGN "Config")."""

from __future__ import annotations

import json
import os
import platform
import subprocess
import sys
import tempfile
from contextlib import contextmanager
from datetime import datetime, timezone
from importlib.metadata import PackageNotFoundError, version
from pathlib import Path
from typing import Iterator

PROVENANCE_PACKAGES = ("numpy", "numba", "pandas", "pyarrow", "hydra-core", "omegaconf", "matplotlib", "torch")


@contextmanager
def atomic_path(path: str | os.PathLike) -> Iterator[Path]:
    """Yield a temporary path beside ``path``; rename it into place only if the block succeeds."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(prefix=f".{path.name}.", suffix=path.suffix, dir=path.parent)
    os.close(fd)
    tmp_path = Path(tmp)
    try:
        yield tmp_path
        os.replace(tmp_path, path)
    finally:
        if tmp_path.exists():
            tmp_path.unlink()


def write_text_atomic(path: str | os.PathLike, text: str) -> None:
    """Write ``text`` to ``path`` atomically."""
    with atomic_path(path) as tmp:
        tmp.write_text(text)


def _git_commit() -> str | None:
    try:
        here = Path(__file__).resolve().parent
        out = subprocess.run(["git", "rev-parse", "HEAD"], cwd=here, capture_output=True, text=True, timeout=5)
        return out.stdout.strip() or None if out.returncode == 0 else None
    except (OSError, subprocess.SubprocessError):
        return None


def provenance(started: datetime, extra: dict | None = None) -> dict:
    """efish version, git commit, package versions, command line, start and end time."""
    from ._version import __version__

    packages = {}
    for name in PROVENANCE_PACKAGES:
        try:
            packages[name] = version(name)
        except PackageNotFoundError:
            continue
    return {
        "efish_version": __version__, "git_commit": _git_commit(), "python": sys.version.split()[0],
        "platform": platform.platform(), "packages": packages, "command": sys.argv,
        "started": started.isoformat(), "finished": datetime.now(timezone.utc).isoformat(), **(extra or {}),
    }


def write_run_metadata(folder: str | os.PathLike, config_yaml: str, started: datetime, extra: dict | None = None) -> None:
    """``config.yaml`` (fully resolved) and ``provenance.json`` beside an output."""
    folder = Path(folder)
    write_text_atomic(folder / "config.yaml", config_yaml)
    write_text_atomic(folder / "provenance.json", json.dumps(provenance(started, extra), indent=2) + "\n")
