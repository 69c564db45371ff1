"""Parameter sweeps of the Skyrmion Reshuffler, serial or on Dask, into a resumable zarr store.

- :func:`load_sweep` / :func:`parse_sweep`: read and fully validate a sweep file (grid or list
  of points over any config field, replicas, a root seed from which every run's seed derives);
- :func:`run_sweep`: run what is not yet done (local Dask cluster, an existing scheduler, or
  serially) and stream each finished run into the store; :func:`start_local_cluster` starts a
  local cluster with the settings a sweep uses;
- :func:`open_sweep`: the store as an :class:`xarray.Dataset`; :func:`open_sweeps`: several
  stores over the same fields as one;
- :func:`fit_current_scaling`, :func:`fit_chamber_scaling`: the paper's scaling fits;
- :func:`plot_sweep`: the paper's reshuffler and chamber-size figures from a store.

See ``docs/sweeps.md``.
"""

# The public names are imported on first use (SPEC 1 lazy loading; the names and their modules
# are listed once, in __init__.pyi, which type checkers read too). A Dask worker of a sweep
# imports only what a run needs this way, not xarray, zarr or the plotting code.
import lazy_loader

__getattr__, __dir__, __all__ = lazy_loader.attach_stub(__name__, __file__)
