"""efish: MARL-trained weakly electric fish collectives, reproduced.

The top-level names load lazily: ``import efish`` (and ``import efish.figures``
or ``efish.analysis``) loads neither numba nor torch; ``efish.sense`` compiles
the physics kernels on first use.
"""

from __future__ import annotations

from importlib import import_module
from typing import Any

from ._version import __version__

# name -> module that defines it
_LAZY = {
    "Snapshot": "efish.physics.snapshot",
    "SnapshotBatch": "efish.physics.snapshot",
    "sense": "efish.sensors.sense",
    "sense_batch": "efish.sensors.sense",
}

__all__ = ["Snapshot", "SnapshotBatch", "__version__", "sense", "sense_batch"]


def __getattr__(name: str) -> Any:
    if name in _LAZY:
        return getattr(import_module(_LAZY[name]), name)
    raise AttributeError(f"module 'efish' has no attribute {name!r}")


def __dir__() -> list[str]:
    return sorted(__all__)
