"""skygas: stochastic Thiele simulation of magnetic skyrmion gases and skyrmionic devices.

The public API:

- materials: :func:`preset`, :func:`load_material`, :class:`Material`, :func:`derive_thiele`,
  :class:`ThieleParameters`;
- geometry: :func:`disk`, :func:`rectangle`, :func:`polygon`, :func:`union`,
  :func:`chamber_with_conduits`, :class:`Outline`;
- the engine: :class:`Simulation`;
- configuration files: :func:`load_config`, :class:`SimulationConfig`, :func:`run_simulation`;
- errors: :class:`InputError`.

Sub-packages: :mod:`skygas.sc` (stochastic computing), :mod:`skygas.micromag` (micromagnetic
bridge). Everything else is private and may change.
"""

from skygas._version import __version__
from skygas.config import SimulationConfig, load_config
from skygas.engine import Simulation
from skygas.errors import InputError
from skygas.geometry import Outline, chamber_with_conduits, disk, polygon, rectangle, union
from skygas.materials import (
    Material,
    ThieleParameters,
    derive_thiele,
    load_material,
    preset,
    preset_names,
)
from skygas.runner import run_simulation

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
