"""Names of :mod:`skygas`, imported on first use (see ``__init__.py``)."""

from . import (
    analysis,
    calibration,
    engine,
    fields,
    figures,
    inference,
    micromag,
    movies,
    neuron,
    optimize,
    outputs,
    physics,
    reservoir,
    reshuffler,
    runs,
    sc,
    sweep,
)
from ._version import __version__
from .core.errors import InputError
from .engine import Simulation
from .figures.plotting import plot
from .physics.geometry import Outline, chamber_with_conduits, disk, polygon, rectangle, union
from .physics.materials import (
    Material,
    ThieleParameters,
    derive_thiele,
    load_material,
    preset,
    preset_names,
)
from .runs.config import SimulationConfig, load_config
from .runs.runner import run_simulation

__all__ = [
    "__version__",
    "InputError",
    "Material",
    "Outline",
    "Simulation",
    "SimulationConfig",
    "ThieleParameters",
    "chamber_with_conduits",
    "derive_thiele",
    "disk",
    "load_config",
    "load_material",
    "plot",
    "polygon",
    "preset",
    "preset_names",
    "rectangle",
    "run_simulation",
    "union",
    # the public modules
    "analysis",
    "calibration",
    "engine",
    "fields",
    "figures",
    "inference",
    "micromag",
    "movies",
    "neuron",
    "optimize",
    "outputs",
    "physics",
    "reservoir",
    "reshuffler",
    "runs",
    "sc",
    "sweep",
]
