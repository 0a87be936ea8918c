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
    assert folder == tmp_path / "efish" / "numba" / _numba_cache.source_digest()
    assert numba.config.CACHE_DIR == str(folder)


def test_a_user_cache_dir_wins(monkeypatch):
    monkeypatch.setenv("NUMBA_CACHE_DIR", "/somewhere/else")
    monkeypatch.setattr(numba.config, "CACHE_DIR", "unchanged")
    assert _numba_cache.configure() is None
    assert numba.config.CACHE_DIR == "unchanged"
