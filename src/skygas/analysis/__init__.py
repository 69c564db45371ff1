"""Standard observables of a skyrmion gas, for any run's recorded positions.

- :class:`Frames`: positions as one table of entries (dense and sparse records alike);
- :func:`mean_squared_displacement`: MSD over overlapping time origins and the diffusion
  constant, with jackknife standard errors, and :func:`diffusion_estimate`: the short- and
  long-time diffusion constants only where the record supports them
  (:mod:`~skygas.analysis.diffusion`);
- :func:`pair_correlation`: g(r) normalised for the confinement (:mod:`~skygas.analysis.structure`);
- :func:`mean_velocity`, :func:`hall_angle`: drift and the skyrmion Hall angle
  (:mod:`~skygas.analysis.transport`);
- :func:`density_map`, :func:`velocity_map`, :func:`occupancy` (:mod:`~skygas.analysis.maps`);
- :func:`analyze`: all of them for one run (what ``skygas analyze`` prints).

These are device-independent; the device-specific analyses stay beside their devices
(:mod:`skygas.reshuffler.analysis`, :mod:`skygas.neuron.analysis`, :mod:`skygas.sweep.analysis`).
"""

from skygas.analysis.diffusion import (
    DiffusionEstimate,
    MSDResult,
    diffusion_estimate,
    mean_squared_displacement,
)
from skygas.analysis.frames import Frames
from skygas.analysis.maps import FieldMap, density_map, occupancy, velocity_map
from skygas.analysis.observables import analyze
from skygas.analysis.structure import PairCorrelation, pair_correlation
from skygas.analysis.transport import MeanVelocity, hall_angle, mean_velocity

__all__ = [
    "Frames",
    "MSDResult",
    "mean_squared_displacement",
    "DiffusionEstimate",
    "diffusion_estimate",
    "PairCorrelation",
    "pair_correlation",
    "MeanVelocity",
    "mean_velocity",
    "hall_angle",
    "FieldMap",
    "density_map",
    "velocity_map",
    "occupancy",
    "analyze",
]
