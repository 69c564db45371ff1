"""The Skyrmion Reshuffler (paper, "Skyrmion Reshuffler"): two chambers that reshuffle bits.

They decorrelate a stochastic bitstream while preserving its p-value.

- :func:`run_reshuffler` runs a configuration and writes its dataset, figures and summary;
- :class:`ReshufflerConfig`, :func:`load_reshuffler_config`: configuration (TOML, presets
  ``default`` and ``paper``);
- :class:`ReshufflerRun`, :func:`summarize`: the same steps one by one, from Python.
"""

# The public names are imported on first use (SPEC 1 lazy loading; the names and their modules
# are listed once, in __init__.pyi, which type checkers read too). A Dask worker of a sweep
# imports only what a run needs this way, not xarray, zarr or the plotting code.
import lazy_loader

__getattr__, __dir__, __all__ = lazy_loader.attach_stub(__name__, __file__)
