"""Atomic writes and provenance for every output folder (docs/architecture.md#config)."""

from __future__ import annotations

import json
import os
import platform
import re
import subprocess
import sys
import tempfile
from contextlib import ExitStack, contextmanager
from datetime import datetime, timezone
from importlib.metadata import PackageNotFoundError, version
from pathlib import Path
from typing import Any, Iterator

_PARTIAL = re.compile(r"^\..+\.[a-z0-9_]{8}(\.[A-Za-z0-9]+)?$")  # tempfile.mkstemp names of atomic_path
PROVENANCE_PACKAGES = ("numpy", "numba", "pandas", "pyarrow", "hydra-core", "omegaconf", "matplotlib", "torch")


def _file_mode() -> int:
    """0666 minus the process umask: the mode ``open(path, "w")`` gives a new file."""
    umask = os.umask(0)
    os.umask(umask)
    return 0o666 & ~umask


_FILE_MODE = _file_mode()


@contextmanager
def atomic_path(path: str | os.PathLike, commit: bool = True) -> Iterator[Path]:
    """Yield a temporary path beside ``path``; rename it into place only if the block succeeds.

    ``commit=False`` leaves the rename to the caller (several files renamed
    together); the temporary file is removed on leaving the block either way.
    """
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(prefix=f".{path.name}.", suffix=path.suffix, dir=path.parent)
    os.close(fd)
    tmp_path = Path(tmp)
    tmp_path.chmod(_FILE_MODE)  # mkstemp makes 0600; outputs get the mode a plain open() would give them
    try:
        yield tmp_path
        if commit:
            os.replace(tmp_path, path)
    finally:
        if tmp_path.exists():
            tmp_path.unlink()


def write_parquet_tables(tables: dict[str, Any], folder: str | os.PathLike) -> list[Path]:
    """``<folder>/<name>.parquet`` for every table (a pandas DataFrame or a pyarrow Table), all or none.

    Every table is written to a temporary file first, and only when all writes
    succeeded are they renamed into place: a failing write (a full disk) leaves
    the folder as it was, never a half-written table nor a new table beside old ones.
    """
    import pyarrow as pa
    import pyarrow.parquet as pq

    folder = Path(folder)
    with ExitStack() as stack:
        staged = {}
        for name, table in tables.items():
            tmp = stack.enter_context(atomic_path(folder / f"{name}.parquet", commit=False))
            arrow = table if isinstance(table, pa.Table) else pa.Table.from_pandas(table, preserve_index=False)
            pq.write_table(arrow, tmp, compression="zstd")
            staged[name] = tmp
        for name, tmp in staged.items():
            os.replace(tmp, folder / f"{name}.parquet")
    return [folder / f"{name}.parquet" for name in tables]


def read_parquet(path: str | os.PathLike, what: str = "a table"):
    """A Parquet file as a DataFrame; a truncated or foreign file is one clear ``ValueError`` naming it.

    A missing file stays a ``FileNotFoundError`` (an ``OSError``, which the CLI reports in one line too).
    The file is read through one open handle: a table that :func:`atomic_path` replaces while it is read (a
    training's ``metrics.parquet``, rewritten every update) is read whole, old or new. ``pd.read_parquet(path)``
    takes the file's size and then opens it again, so a replacement between the two reads a torn table.
    """
    import pandas as pd

    try:
        with open(path, "rb") as handle:
            return pd.read_parquet(handle)
    except OSError:
        raise
    except Exception as exc:  # pyarrow raises its own types for files that are not Parquet
        raise ValueError(f"cannot read {path} as {what} ({type(exc).__name__}): rerun the job that writes it") from None


def remove_partial_writes(folder: str | os.PathLike) -> list[Path]:
    """Delete the temporary files :func:`atomic_path` leaves when its process is killed (SIGKILL skips cleanup).

    They are named ``.<output name>.<8 random characters><suffix>``; nothing else is touched.
    """
    folder = Path(folder)
    if not folder.is_dir():
        return []
    stale = [p for p in folder.iterdir() if p.is_file() and _PARTIAL.match(p.name)]
    for path in stale:
        path.unlink(missing_ok=True)
    return stale


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


def write_run_metadata(folder: str | os.PathLike, config_yaml: str, started: datetime, extra: dict | None = None,
                       name: str = "provenance.json") -> None:
    """``config.yaml`` (fully resolved) and a provenance file (``name``) beside an output.

    Folders that hold several outputs of one run (figure panels) give each its
    own provenance file, ``<output>.provenance.json``; their config is the run's.
    """
    folder = Path(folder)
    write_text_atomic(folder / "config.yaml", config_yaml)
    write_text_atomic(folder / name, json.dumps(provenance(started, extra), indent=2) + "\n")


#: What :func:`write_table_file` writes, by the file's suffix.
TABLE_SUFFIXES = (".parquet", ".csv")


def write_table_file(table, path: str | os.PathLike) -> Path:
    """A pandas table as Parquet or CSV by ``path``'s suffix (no index), written atomically; another suffix is one
    ValueError naming the two."""
    path = Path(path)
    if path.suffix not in TABLE_SUFFIXES:
        raise ValueError(f"--out {path}: the table is written as {' or '.join(TABLE_SUFFIXES)}")
    path.parent.mkdir(parents=True, exist_ok=True)
    with atomic_path(path) as tmp:
        if path.suffix == ".parquet":
            table.to_parquet(tmp, index=False)
        else:
            table.to_csv(tmp, index=False)
    return path
