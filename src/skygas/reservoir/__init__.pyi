"""Names of :mod:`skygas.reservoir`, imported on first use (see ``__init__.py``)."""

from .boltzmann import boltzmann_wall_distance_pdf
from .chamber import build_chamber, contact_middles
from .config import ReservoirConfig, load_reservoir_config, reservoir_config
from .device import ReservoirDevice, StreamResult, StreamRun, StreamSpec
from .drive import Drive
from .files import ReservoirJob, run_reservoir
from .readout import fit_and_score, split
from .sensors import coverage, disk_overlap_area
from .streams import StreamPool, run_streams, stream_specs
from .study import run_study, score_streams, study_summary
from .tasks import BOOLEAN_NAMES, boolean_study, boolean_value, temporal_study

__all__ = [
    "BOOLEAN_NAMES",
    "Drive",
    "ReservoirConfig",
    "ReservoirDevice",
    "ReservoirJob",
    "StreamPool",
    "StreamResult",
    "StreamRun",
    "StreamSpec",
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
    "run_reservoir",
    "run_streams",
    "run_study",
    "score_streams",
    "split",
    "stream_specs",
    "study_summary",
    "temporal_study",
]
