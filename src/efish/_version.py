"""The installed version of efish, without importing anything else of the package."""

from importlib.metadata import PackageNotFoundError, version

try:
    __version__ = version("efish")
except PackageNotFoundError:  # running from a source tree without installation
    __version__ = "0+unknown"
