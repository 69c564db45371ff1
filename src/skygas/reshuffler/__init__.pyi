"""Names of :mod:`skygas.reshuffler`, imported on first use (see ``__init__.py``)."""

from .analysis import ReshufflerResult, summarize
from .config import (
    ReshufflerConfig,
    load_reshuffler_config,
    parse_reshuffler_config,
)
from .files import run_reshuffler
from .run import ReshufflerRun

__all__ = [
    "ReshufflerConfig",
    "ReshufflerResult",
    "ReshufflerRun",
    "load_reshuffler_config",
    "parse_reshuffler_config",
    "run_reshuffler",
    "summarize",
]
