"""Where numba keeps efish's compiled kernels, keyed by the content of the sources they are compiled from.

numba's on-disk cache (``cache=True``) checks only the source file of the
function it compiled; when a helper it inlines from another file changes, it
would load stale machine code. So the cache folder is keyed by a hash of every
file a kernel can be compiled from: the packages that define or inline
kernels (``physics``, ``sensors``, ``env``), the rollout's and the benchmark's
modules that define their own, and this cache's own modules. Editing an analysis, a figure
or the CLI keeps the compiled kernels (rebuilding them takes minutes); editing
a physics module starts from a fresh folder.
"""

from __future__ import annotations

import hashlib
import os
from collections.abc import Iterable
from pathlib import Path

PACKAGE = Path(__file__).resolve().parent
#: Folders and files (relative to the package) that kernels are compiled from or inline.
KERNEL_SOURCES = ("physics", "sensors", "env", "rollout/measure_kernels.py", "bench/multipole.py", "_jit.py",
                  "_numba_cache.py")


def _digest(files: Iterable[Path]) -> str:
    h = hashlib.sha256()
    for path in sorted(files):
        h.update(str(path.relative_to(PACKAGE)).encode())
        h.update(path.read_bytes())
    return h.hexdigest()[:16]


def source_digest() -> str:
    """Short hash of every ``.py`` file of the package (names and contents): changes with any edit."""
    return _digest(PACKAGE.rglob("*.py"))


def kernel_digest() -> str:
    """Short hash of the sources in :data:`KERNEL_SOURCES` (names and contents): the numba cache's key."""
    files = []
    for entry in KERNEL_SOURCES:
        path = PACKAGE / entry
        files += list(path.rglob("*.py")) if path.is_dir() else [path]
    return _digest(files)


def configure() -> Path | None:
    """Point numba's cache at ``$XDG_CACHE_HOME/efish/numba/<kernel digest>`` unless the user chose a folder
    (``NUMBA_CACHE_DIR``). Must run before any efish kernel is defined."""
    if os.environ.get("NUMBA_CACHE_DIR"):
        return None
    import numba

    base = Path(os.environ.get("XDG_CACHE_HOME") or Path.home() / ".cache") / "efish" / "numba"
    folder = base / kernel_digest()
    numba.config.CACHE_DIR = str(folder)
    return folder
