"""efish.io: atomic writes give outputs the mode a plain open() would, not mkstemp's private 0600, and the record
beside every output says which efish made it."""

from __future__ import annotations

import json
import os
import stat
from datetime import datetime, timezone

import efish
from efish.io import atomic_path, write_run_metadata


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


def test_provenance_records_the_efish_version_beside_the_config(tmp_path):
    """What ``efish --version`` prints is what each output's provenance.json says made it."""
    write_run_metadata(tmp_path, "scale: smoke\n", datetime.now(timezone.utc), {"overrides": ["scale=smoke"]},
                       name="panel.provenance.json")
    prov = json.loads((tmp_path / "panel.provenance.json").read_text())
    assert prov["efish_version"] == efish.__version__ and prov["efish_version"]
    assert prov["overrides"] == ["scale=smoke"] and (tmp_path / "config.yaml").read_text() == "scale: smoke\n"
