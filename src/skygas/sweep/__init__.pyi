"""Names of :mod:`skygas.sweep`, imported on first use (see ``__init__.py``)."""

from .analysis import (
    fit_chamber_scaling,
    fit_current_scaling,
    replica_mean,
    running_mean,
)
from .execute import SweepReport, run_sweep, start_local_cluster
from .figures import plot_sweep
from .spec import Run, Sweep, load_sweep, parse_sweep
from .store import open_sweep, open_sweeps
from .worker import run_one

__all__ = [
    "Run",
    "Sweep",
    "SweepReport",
    "fit_chamber_scaling",
    "fit_current_scaling",
    "load_sweep",
    "open_sweep",
    "open_sweeps",
    "parse_sweep",
    "plot_sweep",
    "replica_mean",
    "run_one",
    "run_sweep",
    "running_mean",
    "start_local_cluster",
]
