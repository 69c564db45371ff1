"""The reshuffler's hardware: two identical chambers, their sites and read-outs, and the current.

Their nucleation sites and read-outs, and the current that drives skyrmions through them (paper,
"Skyrmion Reshuffler"; docs/physics.md §3).

Layout: the UP chamber sits above the DOWN chamber, each the paper's disk with an input conduit
on the left and an output conduit on the right
(:func:`~skygas.physics.geometry.chamber_with_conduits`). For the current, both conduit ends are
electrodes. For skyrmions, only the output end is open: it is the read-out line, where a skyrmion is
detected and removed. The input end is the end of the track: a wall. So every skyrmion is either
detected, still present or annihilated.

Each chamber carries its own copy of the current solved for one chamber (the chambers are
identical and driven in parallel), so the Joule power of the device is twice one chamber's.
"""

from __future__ import annotations

import functools
from dataclasses import dataclass

import numpy as np
from shapely.geometry import MultiPolygon

from skygas.core.config_types import CHAMBER_DIAMETER, CHAMBER_GAP, CONDUIT_LENGTH, CONDUIT_WIDTH
from skygas.core.errors import require
from skygas.core.memo import Memo, frozen
from skygas.core.units import M_TO_NM
from skygas.physics.geometry import Outline, chamber_with_conduits

CHAMBERS = ("up", "down")


@dataclass(frozen=True)
class ReshufflerGeometry:
    """Dimensions of one chamber [m] and the spacing between the two chambers [m]."""

    chamber_diameter: float = CHAMBER_DIAMETER
    conduit_width: float = CONDUIT_WIDTH
    conduit_length: float = CONDUIT_LENGTH
    chamber_gap: float = CHAMBER_GAP

    def chamber(self) -> Outline:
        """One chamber centred at the origin, ports ``input`` and ``output`` (electrodes)."""
        return _chamber(self.chamber_diameter, self.conduit_width, self.conduit_length)

    def centres(self) -> dict[str, tuple[float, float]]:
        """Centre [m] of each chamber."""
        offset = (self.chamber_diameter + self.chamber_gap) / 2
        return {"up": (0.0, offset), "down": (0.0, -offset)}

    def device_outline(self) -> Outline:
        """Both chambers, with ports ``up.output`` and ``down.output`` (read-out lines)."""
        return _device_outline(self)

    def nucleation_sites(self) -> dict[str, np.ndarray]:
        """Nucleation site [nm] of each chamber: the middle of its input conduit."""
        half_w = self.conduit_width / 2
        r = self.chamber_diameter / 2
        x_meet = np.sqrt(r * r - half_w * half_w)
        x_site = -(x_meet + self.conduit_length / 2)
        return {
            name: np.array([x_site + cx, cy]) * M_TO_NM for name, (cx, cy) in self.centres().items()
        }

    def chamber_of(self, y_nm) -> np.ndarray:
        """Index into :data:`CHAMBERS` of the chamber a point with ordinate y [nm] belongs to."""
        return np.where(np.asarray(y_nm) >= 0.0, 0, 1)

    def validate(self, skyrmion_diameter: float) -> None:
        """Refuse chambers narrower than a skyrmion and conduits that do not fit."""
        require(
            self.chamber_diameter > skyrmion_diameter,
            "chamber_diameter",
            self.chamber_diameter,
            f"a diameter larger than the skyrmion diameter ({skyrmion_diameter:.3g} m)",
        )
        require(
            self.conduit_width > skyrmion_diameter,
            "conduit_width",
            self.conduit_width,
            f"a width larger than the skyrmion diameter ({skyrmion_diameter:.3g} m)",
        )
        require(
            self.conduit_width < self.chamber_diameter,
            "conduit_width",
            self.conduit_width,
            f"a width smaller than the chamber diameter ({self.chamber_diameter:.3g} m)",
        )
        require(
            self.conduit_length >= skyrmion_diameter / 2,
            "conduit_length",
            self.conduit_length,
            f"a length of at least half a skyrmion diameter ({skyrmion_diameter / 2:.3g} m)",
        )
        require(self.chamber_gap > 0, "chamber_gap", self.chamber_gap, "a gap > 0 in metres")


# Outlines are immutable and cost a few ms of shapely work each: a sweep's runs of one
# device share them.
_chamber = functools.lru_cache(maxsize=8)(chamber_with_conduits)


@functools.lru_cache(maxsize=8)
def _device_outline(geometry: ReshufflerGeometry) -> Outline:
    pieces, ports = [], {}
    for name, (cx, cy) in geometry.centres().items():
        moved = geometry.chamber().translated(cx, cy)
        pieces.append(moved.region)
        ports[f"{name}.output"] = moved.ports["output"]
    return Outline(MultiPolygon(pieces), ports)


def drift_field_on_grid(
    geometry: ReshufflerGeometry, solution, grid, spin_drift_coefficient: float
) -> tuple[np.ndarray, np.ndarray]:
    """v_s = ξ·j [m/s] on the simulation grid: the one-chamber current copied into both chambers.

    ``solution`` is a :class:`~skygas.fields.current.CurrentSolution` of one chamber centred at the
    origin; ``grid`` the engine's :class:`~skygas.fields.wall_field.Grid` (nm).

    The current is linear in J: its field for J = 1 A/m² is sampled on the grid once per
    process for each device and grid (:mod:`skygas.core.memo`) and every run scales it by ξJ, so
    runs that differ in J (or p, temperature, …) do not sample the solution again.
    """
    key = (geometry, grid, solution.cell_grid, solution.sources, solution.sinks)
    jx, jy = _UNIT_SAMPLE.get(
        key, lambda: _sample_both_chambers(geometry, solution.at_current_density(1.0), grid)
    )
    scale = spin_drift_coefficient * solution.current_density
    return scale * jx, scale * jy


# (geometry, grid, cells, electrodes) → (jx, jy) [A/m²] on the grid for J = 1 A/m²
_UNIT_SAMPLE = Memo("drift_unit_sample", maxsize=2, persist=True)


def _sample_both_chambers(
    geometry: ReshufflerGeometry, solution, grid
) -> tuple[np.ndarray, np.ndarray]:
    gx, gy = grid.nodes()
    which = geometry.chamber_of(gy)
    jx = np.zeros((grid.ny, grid.nx))
    jy = np.zeros((grid.ny, grid.nx))
    for index, name in enumerate(CHAMBERS):
        cx, cy = geometry.centres()[name]
        mask = which == index
        jx[mask], jy[mask] = solution.current_density_at(
            gx[mask] / M_TO_NM - cx, gy[mask] / M_TO_NM - cy
        )
    frozen(jx, jy)
    return jx, jy
