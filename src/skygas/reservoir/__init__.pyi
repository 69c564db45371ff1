"""Names of :mod:`skygas.reservoir`, imported on first use (see ``__init__.py``)."""

from .boltzmann import boltzmann_wall_distance_pdf
from .chamber import build_chamber, contact_middles
from .config import ReservoirConfig, load_reservoir_config, reservoir_config
from .device import ReservoirDevice, StreamResult, run_streams
from .drive import Drive
from .readout import fit_and_score, split
from .sensors import coverage, disk_overlap_area
from .study import accuracy_sweep, run_study, score_streams
from .tasks import BOOLEAN_NAMES, boolean_study, boolean_value, temporal_study

__all__ = [
    "BOOLEAN_NAMES",
    "Drive",
    "ReservoirConfig",
    "ReservoirDevice",
    "StreamResult",
    "accuracy_sweep",
    "boltzmann_wall_distance_pdf",
    "boolean_study",
    "boolean_value",
    "build_chamber",
    "contact_middles",
    "coverage",
    "disk_overlap_area",
    "fit_and_score",
    "load_reservoir_config",
    "reservoir_config",
    "run_streams",
    "run_study",
    "score_streams",
    "split",
    "temporal_study",
]
