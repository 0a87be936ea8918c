"""Where numba keeps efish's compiled kernels, keyed by the content of efish's sources.

numba's on-disk cache (``cache=True``) checks only the source file of the
function it compiled; when a helper it inlines from another file changes, it
would load stale machine code. Keying the cache folder by a hash of every
efish source file makes any edit or upgrade start from a fresh folder.
"""

from __future__ import annotations

import hashlib
import os
from pathlib import Path

PACKAGE = Path(__file__).resolve().parent


def source_digest() -> str:
    """Short hash of every ``.py`` file of the package (names and contents)."""
    h = hashlib.sha256()
    for path in sorted(PACKAGE.rglob("*.py")):
        h.update(str(path.relative_to(PACKAGE)).encode())
        h.update(path.read_bytes())
    return h.hexdigest()[:16]


def configure() -> Path | None:
    """Point numba's cache at ``$XDG_CACHE_HOME/efish/numba/<digest>`` unless the user chose a folder
    (``NUMBA_CACHE_DIR``). Must run before any efish kernel is defined."""
    if os.environ.get("NUMBA_CACHE_DIR"):
        return None
    import numba

    base = Path(os.environ.get("XDG_CACHE_HOME") or Path.home() / ".cache") / "efish" / "numba"
    folder = base / source_digest()
    numba.config.CACHE_DIR = str(folder)
    return folder
