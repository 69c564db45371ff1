"""What a sweep's worker runs: one configuration in, the numbers a sweep stores out.

A run is its kind's study hook (:func:`~skygas.devices.study_hooks.run_point`, which imports only
that kind: a fresh Dask worker then imports the simulation, not zarr, xarray or pandas, ~0.7 s of
imports per worker process; :mod:`skygas.sweep` exports its names lazily for the same reason).
The reshuffler's hooks are named here as the sweep's first device.
"""

from __future__ import annotations

from skygas.devices.study_hooks import run_point
from skygas.reshuffler.study_points import QUANTITIES, RUNNING
from skygas.reshuffler.study_points import run as run_one

__all__ = ["QUANTITIES", "RUNNING", "run_one", "run_point"]
