"""Parameter sweeps of the Skyrmion Reshuffler, serial or on Dask, into a resumable zarr store.

- :func:`load_sweep` / :func:`parse_sweep`: read and fully validate a sweep file (grid or list
  of points over any config field, replicas, a root seed from which every run's seed derives);
- :func:`run_sweep`: run what is not yet done (local Dask cluster, an existing scheduler, or
  serially) and stream each finished run into the store; :func:`start_local_cluster` starts a
  local cluster with the settings a sweep uses;
- :func:`open_sweep`: the store as an :class:`xarray.Dataset`;
- :func:`fit_current_scaling`, :func:`fit_chamber_scaling`: the paper's scaling fits;
- :func:`plot_sweep`: the paper's reshuffler and chamber-size figures from a store.

See ``docs/sweeps.md``.
"""

from skygas.sweep.analysis import (
    fit_chamber_scaling,
    fit_current_scaling,
    replica_mean,
    running_mean,
)
from skygas.sweep.execute import SweepReport, run_one, run_sweep, start_local_cluster
from skygas.sweep.figures import plot_sweep
from skygas.sweep.spec import Run, Sweep, load_sweep, parse_sweep
from skygas.sweep.store import open_sweep

__all__ = [
    "Run",
    "Sweep",
    "SweepReport",
    "fit_chamber_scaling",
    "fit_current_scaling",
    "load_sweep",
    "open_sweep",
    "parse_sweep",
    "plot_sweep",
    "replica_mean",
    "run_one",
    "run_sweep",
    "running_mean",
    "start_local_cluster",
]
