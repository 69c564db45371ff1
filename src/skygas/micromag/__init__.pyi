"""Names of :mod:`skygas.micromag`, imported on first use (see ``__init__.py``)."""

from .detection import Skyrmion, Snapshot, detect_skyrmions, inspect_field
from .export import material_preset, write_material_toml
from .forces import (
    DiskBoundary,
    LawFit,
    LawTable,
    LineBoundary,
    UnfixedLawError,
    fit_pair_law,
    fit_wall_law,
    law_problem,
    pair_law_magnitude,
    tabulate_law,
    thiele_forces,
    velocities,
    wall_law_magnitude,
)
from .ovf import (
    OVFMesh,
    OVFUnitWarning,
    field_from_array,
    load_field,
    read_mesh,
    read_ovf,
    write_ovf,
)
from .topology import charge_density, dissipation, topological_charge
from .tracking import Trajectory, link
from .workflow import FitResult, fit_snapshots, fit_trajectories

__all__ = [
    "DiskBoundary",
    "FitResult",
    "LawFit",
    "LawTable",
    "LineBoundary",
    "OVFMesh",
    "OVFUnitWarning",
    "Skyrmion",
    "Snapshot",
    "Trajectory",
    "UnfixedLawError",
    "charge_density",
    "detect_skyrmions",
    "dissipation",
    "field_from_array",
    "fit_pair_law",
    "fit_snapshots",
    "fit_trajectories",
    "fit_wall_law",
    "inspect_field",
    "law_problem",
    "link",
    "load_field",
    "material_preset",
    "pair_law_magnitude",
    "read_mesh",
    "read_ovf",
    "tabulate_law",
    "thiele_forces",
    "topological_charge",
    "velocities",
    "wall_law_magnitude",
    "write_material_toml",
    "write_ovf",
]
