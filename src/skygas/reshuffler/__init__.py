"""The Skyrmion Reshuffler (paper, "Skyrmion Reshuffler"): two chambers that decorrelate a
stochastic bitstream while preserving its p-value.

- :func:`run_reshuffler` runs a configuration and writes its dataset, figures and summary;
- :class:`ReshufflerConfig`, :func:`load_reshuffler_config`: configuration (TOML, presets
  ``default`` and ``paper``);
- :class:`ReshufflerRun`, :func:`summarize`: the same steps one by one, from Python.
"""

from skygas.reshuffler.analysis import ReshufflerResult, summarize
from skygas.reshuffler.config import (
    ReshufflerConfig,
    load_reshuffler_config,
    parse_reshuffler_config,
)
from skygas.reshuffler.files import run_reshuffler
from skygas.reshuffler.run import ReshufflerRun

__all__ = [
    "ReshufflerConfig",
    "ReshufflerResult",
    "ReshufflerRun",
    "load_reshuffler_config",
    "parse_reshuffler_config",
    "run_reshuffler",
    "summarize",
]
