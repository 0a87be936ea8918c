"""efish.io: atomic writes give outputs the mode a plain open() would, not mkstemp's private 0600."""

from __future__ import annotations

import os
import stat

from efish.io import atomic_path


def test_an_atomic_write_gets_the_umask_mode(tmp_path):
    old = os.umask(0o022)
    try:
        import importlib

        import efish.io

        importlib.reload(efish.io)  # the mode is read from the umask at import
        with efish.io.atomic_path(tmp_path / "table.parquet") as tmp:
            tmp.write_bytes(b"x")
    finally:
        os.umask(old)
        importlib.reload(efish.io)
    assert stat.S_IMODE((tmp_path / "table.parquet").stat().st_mode) == 0o644


def test_a_failed_write_leaves_nothing(tmp_path):
    try:
        with atomic_path(tmp_path / "t.txt") as tmp:
            tmp.write_text("half")
            raise RuntimeError("writer failed")
    except RuntimeError:
        pass
    assert list(tmp_path.iterdir()) == []
