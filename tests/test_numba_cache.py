"""numba's kernel cache is keyed by the content of efish's sources, so no stale machine code is loaded."""

from __future__ import annotations

import numba

from efish import _numba_cache


def test_digest_is_stable_and_short():
    a, b = _numba_cache.source_digest(), _numba_cache.source_digest()
    assert a == b and len(a) == 16 and int(a, 16) >= 0


def test_cache_folder_is_keyed_by_the_sources(monkeypatch, tmp_path):
    monkeypatch.delenv("NUMBA_CACHE_DIR", raising=False)
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path))
    monkeypatch.setattr(numba.config, "CACHE_DIR", numba.config.CACHE_DIR)  # restored after the test
    folder = _numba_cache.configure()
    assert folder == tmp_path / "efish" / "numba" / _numba_cache.kernel_digest()
    assert numba.config.CACHE_DIR == str(folder)


def _copy_package(tmp_path, monkeypatch):
    """A copy of the package's sources that the digests read instead of the installed ones."""
    import shutil

    copy = tmp_path / "efish"
    shutil.copytree(_numba_cache.PACKAGE, copy, ignore=shutil.ignore_patterns("__pycache__"))
    monkeypatch.setattr(_numba_cache, "PACKAGE", copy)
    return copy


def test_editing_a_figure_keeps_the_kernel_cache(monkeypatch, tmp_path):
    copy = _copy_package(tmp_path, monkeypatch)
    kernels, everything = _numba_cache.kernel_digest(), _numba_cache.source_digest()
    with open(copy / "figures" / "fig3.py", "a") as f:
        f.write("\n# an edit\n")
    assert _numba_cache.kernel_digest() == kernels
    assert _numba_cache.source_digest() != everything


def test_editing_a_physics_module_changes_the_kernel_cache(monkeypatch, tmp_path):
    copy = _copy_package(tmp_path, monkeypatch)
    for module in ("physics/kernels.py", "env/dynamics.py", "sensors/encode.py"):
        before = _numba_cache.kernel_digest()
        with open(copy / module, "a") as f:
            f.write("\n# an edit\n")
        assert _numba_cache.kernel_digest() != before, module


def test_a_user_cache_dir_wins(monkeypatch):
    monkeypatch.setenv("NUMBA_CACHE_DIR", "/somewhere/else")
    monkeypatch.setattr(numba.config, "CACHE_DIR", "unchanged")
    assert _numba_cache.configure() is None
    assert numba.config.CACHE_DIR == "unchanged"


def test_every_module_that_defines_kernels_keys_the_cache():
    """A module that imports efish's njit defines kernels: its source must be in the cache's key."""
    covered = set()
    for entry in _numba_cache.KERNEL_SOURCES:
        path = _numba_cache.PACKAGE / entry
        covered |= set(path.rglob("*.py")) if path.is_dir() else {path}
    defining = {p for p in _numba_cache.PACKAGE.rglob("*.py")
                if "from ._jit import njit" in p.read_text() or "from .._jit import njit" in p.read_text()
                or "from ..._jit import njit" in p.read_text()}
    assert defining, "no kernel module found: the test's import pattern is stale"
    assert not sorted(str(p.relative_to(_numba_cache.PACKAGE)) for p in defining - covered)
