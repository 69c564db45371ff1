"""The micromagnetics bridge: from OOMMF/mumax3 magnetisation files to the particle model.

Read OVF snapshots (:func:`read_ovf`), measure the topological charge Q and the dissipation 𝒟
(:func:`topological_charge`, :func:`dissipation`), find skyrmions (:func:`detect_skyrmions`),
link them into trajectories (:func:`link`), turn their motion into forces F = Ĝ^α·ẋ and fit the
paper's pair and wall laws (:func:`fit_trajectories`, :func:`fit_snapshots`), and export the
result as a material preset that :func:`skygas.materials.load_material` reads.
See ``docs/micromagnetics.md``.
"""

from skygas.micromag.detection import Skyrmion, Snapshot, detect_skyrmions, inspect_field
from skygas.micromag.export import material_preset, write_material_toml
from skygas.micromag.forces import (
    DiskBoundary,
    LawFit,
    LineBoundary,
    fit_pair_law,
    fit_wall_law,
    pair_law_magnitude,
    thiele_forces,
    velocities,
    wall_law_magnitude,
)
from skygas.micromag.ovf import field_from_array, load_field, read_ovf, write_ovf
from skygas.micromag.topology import charge_density, dissipation, topological_charge
from skygas.micromag.tracking import Trajectory, link
from skygas.micromag.workflow import FitResult, fit_snapshots, fit_trajectories

__all__ = [
    "DiskBoundary", "FitResult", "LawFit", "LineBoundary", "Skyrmion", "Snapshot", "Trajectory",
    "charge_density", "detect_skyrmions", "dissipation", "field_from_array", "fit_pair_law",
    "fit_snapshots", "fit_trajectories", "fit_wall_law", "inspect_field", "link",
    "load_field", "material_preset", "pair_law_magnitude", "read_ovf", "thiele_forces",
    "topological_charge", "velocities", "wall_law_magnitude", "write_material_toml",
    "write_ovf",
]
