"""efish: MARL-trained weakly electric fish collectives, reproduced."""

from importlib.metadata import PackageNotFoundError, version

try:
    __version__ = version("efish")
except PackageNotFoundError:  # running from a source tree without installation
    __version__ = "0+unknown"

from . import _numba_cache  # noqa: E402

_numba_cache.configure()  # before any kernel is defined: see _numba_cache

from .physics.snapshot import Snapshot, SnapshotBatch  # noqa: E402
from .sensing import sense, sense_batch  # noqa: E402

__all__ = ["Snapshot", "SnapshotBatch", "__version__", "sense", "sense_batch"]
