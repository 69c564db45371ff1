"""Names of :mod:`skygas`, imported on first use (see ``__init__.py``)."""

from ._version import __version__
from .config import SimulationConfig, load_config
from .engine import Simulation
from .errors import InputError
from .geometry import Outline, chamber_with_conduits, disk, polygon, rectangle, union
from .materials import (
    Material,
    ThieleParameters,
    derive_thiele,
    load_material,
    preset,
    preset_names,
)
from .runner import run_simulation

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
    "polygon",
    "preset",
    "preset_names",
    "rectangle",
    "run_simulation",
    "union",
]
