"""Finding skyrmions in a snapshot: regions, sub-cell centres, radii, charges and 𝒟.

1. **Cores.** The background polarity s is the sign of the median m_z over the magnetic cells;
   a core is a connected region (4-neighbour) with s·m_z < ``threshold`` (default 0, i.e.
   reversed magnetisation) of at least ``min_cells`` cells.
2. **Regions.** Every magnetic cell is given to its nearest core (a discrete Voronoi partition
   by the Euclidean distance transform), so a region's integrals pick up the skyrmion's tail and
   nothing of its neighbours' cores.
3. **Centre.** The topological-charge-weighted guiding centre, R = Σ x_p q_p / Σ q_p over the
   region's plaquettes p (Berg–Lüscher density, :mod:`skygas.micromag.topology`). It is the
   guiding centre of Thiele's theory and needs no model of the profile.
4. **Radius.** The m_z = 0 contour, sampled along ``n_rays`` rays from the centre on a cubic
   spline of m_z; the radius is that of the disk of equal area, √(⟨r(φ)²⟩). The ratio of the
   shortest to the longest ray is reported as ``circularity`` (1 for a round skyrmion).
5. **Charge and 𝒟** per region (:func:`~skygas.micromag.topology.topological_charge`,
   :func:`~skygas.micromag.topology.dissipation`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import xarray as xr
from scipy import ndimage

from skygas._version import __version__
from skygas.errors import InputError
from skygas.micromag import topology


@dataclass(frozen=True)
class Skyrmion:
    """One detected skyrmion (SI units).

    Attributes: ``x``, ``y`` guiding centre [m]; ``radius`` [m] (m_z = 0 contour);
    ``charge`` Q of its region; ``dissipation`` 𝒟 of its region; ``area`` of its reversed core
    [m²]; ``circularity`` (shortest / longest contour ray); ``label`` region id in the snapshot.
    """

    x: float
    y: float
    radius: float
    charge: float
    dissipation: float
    area: float
    circularity: float
    label: int


@dataclass(frozen=True)
class Snapshot:
    """The skyrmions of one field, its region labels (ny, nx), total charge and time [s]."""

    skyrmions: tuple[Skyrmion, ...]
    labels: np.ndarray
    total_charge: float
    time: float


def _regions(mz: np.ndarray, magnetic: np.ndarray, threshold: float, min_cells: int):
    background = 1.0 if np.median(mz[magnetic]) >= 0 else -1.0
    reversed_ = magnetic & (background * mz < threshold)
    cores, count = ndimage.label(reversed_)
    sizes = np.bincount(cores.ravel(), minlength=count + 1)
    small = sizes < min_cells
    small[0] = True
    cores[small[cores]] = 0
    cores, count = ndimage.label(cores > 0)
    if count == 0:
        return cores, cores, background
    _, (iy, ix) = ndimage.distance_transform_edt(cores == 0, return_indices=True)
    regions = np.where(magnetic, cores[iy, ix], 0)
    return cores, regions, background


def _contour_radius(mz, background, cx_cells, cy_cells, max_r, n_rays):
    """Radius [cells] of the s·m_z = 0 contour around (cx, cy) in cell-index units."""
    spline = ndimage.spline_filter(mz, order=3)
    steps = np.linspace(0.0, max_r, int(max_r * 20) + 2)
    angles = np.linspace(0.0, 2 * np.pi, n_rays, endpoint=False)
    rows = cy_cells + np.outer(np.sin(angles), steps)
    cols = cx_cells + np.outer(np.cos(angles), steps)
    values = background * ndimage.map_coordinates(spline, [rows.ravel(), cols.ravel()], order=3,
                                                  prefilter=False, mode="nearest")
    values = values.reshape(rows.shape)
    radii = np.full(n_rays, np.nan)
    for k in range(n_rays):
        crossing = np.flatnonzero((values[k, :-1] < 0) & (values[k, 1:] >= 0))
        if crossing.size:
            j = crossing[0]
            v0, v1 = values[k, j], values[k, j + 1]
            radii[k] = steps[j] + (steps[j + 1] - steps[j]) * v0 / (v0 - v1)
    return radii


def detect_skyrmions(
    field: xr.DataArray, threshold: float = 0.0, min_cells: int = 4, n_rays: int = 64
) -> Snapshot:
    """Detect the skyrmions of one snapshot (see the module docstring for the method)."""
    if not -1.0 < threshold < 1.0:
        raise InputError("threshold", threshold, "a value of s·m_z in (−1, 1)")
    n, magnetic = topology.unit_layer(field)
    mz = n[..., 2]
    cores, regions, background = _regions(mz, magnetic, threshold, min_cells)
    density = topology.charge_density(field).values
    total = float(density.sum())
    time = float(field.attrs.get("time", math.nan))
    count = int(regions.max(initial=0))
    if count == 0:
        return Snapshot((), regions, total, time)
    charges = topology.topological_charge(field, regions)
    dissipations = topology.dissipation(field, regions)
    dx, dy = float(field.attrs["dx"]), float(field.attrs["dy"])
    x0, y0 = float(field.x.values[0]), float(field.y.values[0])
    plaquette_labels = regions[:-1, :-1]
    py, px = np.mgrid[0 : density.shape[0], 0 : density.shape[1]] + 0.5  # cell-index units
    core_sizes = np.bincount(cores.ravel(), minlength=count + 1)
    found = []
    for label in range(1, count + 1):
        in_region = plaquette_labels == label
        weight = density[in_region]
        if abs(weight.sum()) > 0.5:
            cx = float((px[in_region] * weight).sum() / weight.sum())
            cy = float((py[in_region] * weight).sum() / weight.sum())
        else:  # a topologically trivial bubble: fall back on the reversed-core centroid
            cy, cx = ndimage.center_of_mass(cores == label)
        max_r = 2.0 * math.sqrt(core_sizes[label] / math.pi) + 3.0
        radii = _contour_radius(mz, background, cx, cy, max_r, n_rays) * math.sqrt(dx * dy)
        good = radii[np.isfinite(radii)]
        radius = float(np.sqrt(np.mean(good**2))) if good.size else math.nan
        found.append(Skyrmion(
            x=x0 + cx * dx, y=y0 + cy * dy, radius=radius, charge=float(charges[label - 1]),
            dissipation=float(dissipations[label - 1]), area=float(core_sizes[label] * dx * dy),
            circularity=float(good.min() / good.max()) if good.size else math.nan,
            label=label,
        ))
    return Snapshot(tuple(found), regions, total, time)


def inspect_field(field: xr.DataArray, **options) -> dict:
    """A JSON-ready summary of one snapshot: per-skyrmion charge, centre, radius and 𝒟.

    Keys: ``skyrmions`` (objects with ``charge``, ``x_m``, ``y_m``, ``radius_m``,
    ``dissipation``, ``area_m2``, ``circularity``), ``total_charge``, ``time_s``, the mesh and
    the detection options.
    """
    snap = detect_skyrmions(field, **options)
    return {
        "skyrmions": [
            {"charge": s.charge, "x_m": s.x, "y_m": s.y, "radius_m": s.radius,
             "dissipation": s.dissipation, "area_m2": s.area, "circularity": s.circularity}
            for s in snap.skyrmions
        ],
        "total_charge": snap.total_charge,
        "time_s": None if math.isnan(snap.time) else snap.time,
        "mesh": {"nx": field.sizes["x"], "ny": field.sizes["y"], "nz": field.sizes["z"],
                 "dx_m": field.attrs["dx"], "dy_m": field.attrs["dy"], "dz_m": field.attrs["dz"]},
        "options": options,
        "skygas_version": __version__,
    }
