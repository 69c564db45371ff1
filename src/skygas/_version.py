"""Package version, read from the installed metadata (single source: pyproject.toml)."""

from importlib.metadata import PackageNotFoundError, version

try:
    __version__ = version("skygas")
except PackageNotFoundError:  # running from a source tree that was never installed
    __version__ = "0+unknown"
