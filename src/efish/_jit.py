"""numba's ``njit``, with efish's kernel cache folder chosen first.

Every kernel module imports ``njit`` from here, never from numba directly:
the cache folder (see :mod:`efish._numba_cache`) must be set before the first
kernel is defined, and this module is the one place that guarantees it.
Importing a module that defines no kernel (configs, analyses, figures) thus
never loads numba.
"""

from . import _numba_cache

_numba_cache.configure()

from numba import njit  # noqa: E402

__all__ = ["njit"]
