"""Fixtures of the efish tests; the helpers they use live in ``tests/helpers.py``."""

from __future__ import annotations

import pytest

from .helpers import cfg_with


@pytest.fixture(scope="session")
def default_cfg():
    """The composed default config (shared, do not mutate)."""
    return cfg_with()


@pytest.fixture(scope="session")
def cfg_factory():
    """``cfg_factory("a.b=1", ...)``: a cached composed config with overrides."""
    return cfg_with
