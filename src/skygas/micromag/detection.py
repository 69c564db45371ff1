"""Finding skyrmions in a snapshot: regions, sub-cell centres, radii, charges and 𝒟.

1. **Cores.** The background polarity s is the sign of the median m_z over the magnetic cells;
   a core is a connected region (4-neighbour) with s·m_z < ``threshold`` (default 0, i.e.
   reversed magnetisation) of at least ``min_cells`` cells.
2. **Film edge.** Magnetisation tilts at a film's edges (the DMI boundary condition), and a
   tilted edge carries topological charge density of its own (a disk's tilted rim holds
   (1 − cos θ_edge)/2 of a skyrmion's charge). The *edge band* is the strip along the film edge
   (empty cells or the mesh border) where the background tilts: the cells closer to the edge
   than the first distance at which the median tilt angle arccos(s·n_z) of the cells at that
   distance is within ``EDGE_TILT_TOLERANCE`` of the film's typical (median) tilt. A film
   without edge tilt has no band.
3. **Neighbourhoods.** Every magnetic cell is first given to its nearest core (a discrete
   Voronoi partition by the Euclidean distance transform), so nothing of a neighbour's core is
   counted. A skyrmion's *neighbourhood* is the part of its Voronoi region outside the edge band
   and within R + ``REACH_WALL_WIDTHS``·Δ of its core's centroid, R and Δ the radius and wall
   width of its m_z profile (step 5). The ansatz's charge density falls as e^{−2(r−R)/Δ}, so the
   neighbourhood holds all of a skyrmion's charge but e^{−12} ≈ 6·10⁻⁶ of it, and no charge of the
   film's edges or of far textures.
   A skyrmion whose tail reaches into the edge band loses the charge there: its |Q| drops below 1
   and its centre moves away from the edge (on the ansatz, R = 10 nm, Δ = 3 nm, an edge tilted
   by 30° with ξ = Δ, band 7 nm: 0.5 nm at 20 nm from the edge, < 0.05 nm from 25 nm on; the
   whole-region centre of earlier versions was off by 0.4–0.6 nm at every distance).
4. **Centre.** The topological-charge-weighted guiding centre, R = Σ x_p q_p / Σ q_p over the
   neighbourhood's plaquettes p (Berg–Lüscher density, :mod:`skygas.micromag.topology`; a
   plaquette counts a quarter for each of its corner cells' regions, so the border between two
   touching skyrmions splits its charge evenly). It is the guiding centre of Thiele's theory
   and needs no model of the profile.
5. **Radius and wall width.** The m_z = 0 contour, sampled along ``n_rays`` rays from the
   centre on a cubic spline of m_z; the radius is that of the disk of equal area, √(⟨r(φ)²⟩).
   The ratio of the shortest to the longest ray is reported as ``circularity`` (1 for a round
   skyrmion). The wall width is Δ = 1/|∂(s·m_z)/∂r| at the contour (the median over the rays):
   for the 360° wall ansatz it is Δ·tanh(R/Δ).
6. **Charge and 𝒟** per neighbourhood (:func:`~skygas.micromag.topology.topological_charge`,
   :func:`~skygas.micromag.topology.dissipation`). ``Snapshot.labels`` holds the
   neighbourhoods (0 elsewhere).

**Two centres by an edge.** Leaving the band out (the default) keeps a curved rim's own charge
out of every skyrmion, but near an edge it also leaves out part of the skyrmion's: the band's
tilt there is the skyrmion's tail bent by the edge. ``edge_band=False`` keeps the band, and the
centre is the guiding centre of all the charge near the skyrmion, Σ x q / Σ q as above over its
whole neighbourhood. That is the coordinate that :mod:`skygas.calibration` holds its relaxations
at and reads its micromagnetic validation runs in, so that its laws and its tracks measure the
same distance. The two differ only within a few wall widths of an edge: S6 (R = 11.6 nm,
Δ = 3.1 nm) held 0.82 d_sk from a straight edge has |Q| = 0.80 and a centre 2.3 nm farther from
the edge without the band, |Q| = 1.00 and the held centre with it. A straight edge's own tilt
carries no charge (m varies across the edge only, so m·(∂ₓm × ∂ᵧm) = 0); a disk's rim of radius
ρ carries (1 − cos θ_edge)/2 spread along its 2πρ, of which a neighbourhood takes a small share.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import xarray as xr
from scipy import ndimage

from skygas._version import __version__
from skygas.core.errors import InputError
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
    """The skyrmions of one field, with their neighbourhood labels.

    The skyrmions, their neighbourhood labels (ny, nx), the total charge, the time [s] and the width
    of the film-edge band [m] (0 without edge tilt).
    """

    skyrmions: tuple[Skyrmion, ...]
    labels: np.ndarray
    total_charge: float
    time: float
    edge_band_width: float = 0.0


#: Neighbourhood radius beyond the m_z = 0 contour, in wall widths (see the module docstring).
REACH_WALL_WIDTHS = 6.0
#: Tilt angle [rad] above the film's typical tilt that marks the film-edge band (1°).
EDGE_TILT_TOLERANCE = math.radians(1.0)


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


def find_edge_band(
    mz: np.ndarray, magnetic: np.ndarray, background: float, cores: np.ndarray | None = None
) -> tuple[np.ndarray, int]:
    """The film-edge band (mask, ny × nx) and its width [cells] (see the module docstring).

    Distances to the edge are counted from each cell centre to the nearest empty cell or the
    mesh border (1 for a cell on the edge). ``cores`` (cells of reversed cores) are left out of
    the tilt statistics, so that skyrmions near the edge do not widen the band.
    """
    depth = ndimage.distance_transform_edt(np.pad(magnetic, 1))[1:-1, 1:-1]
    ring = np.floor(depth).astype(int)  # 1 on the edge, 2 next, ...
    angle = np.arccos(np.clip(background * mz, -1.0, 1.0))
    counted = magnetic & (True if cores is None else cores == 0)
    if not counted.any():
        return np.zeros_like(magnetic), 0
    limit = float(np.median(angle[counted])) + EDGE_TILT_TOLERANCE
    for width in range(int(ring.max()) + 1):
        cells = counted & (ring == width + 1)
        if cells.any() and np.median(angle[cells]) <= limit:
            break
    else:  # no ring as flat as the film: no edge tilt to tell apart
        width = 0
    return magnetic & (ring <= width), width


def _contour_rays(spline, background, cx_cells, cy_cells, max_r, n_rays):
    """Radius [cells] of the s·m_z = 0 contour along each ray around (cx, cy), and the slope there.

    (cx, cy) in cell-index units; the slope is ∂(s·m_z)/∂r [1/cell] (NaN where a ray finds no
    crossing).
    """
    steps = np.linspace(0.0, max_r, int(max_r * 20) + 2)
    angles = np.linspace(0.0, 2 * np.pi, n_rays, endpoint=False)
    rows = cy_cells + np.outer(np.sin(angles), steps)
    cols = cx_cells + np.outer(np.cos(angles), steps)
    values = background * ndimage.map_coordinates(
        spline, [rows.ravel(), cols.ravel()], order=3, prefilter=False, mode="nearest"
    )
    values = values.reshape(rows.shape)
    radii = np.full(n_rays, np.nan)
    slopes = np.full(n_rays, np.nan)
    for k in range(n_rays):
        crossing = np.flatnonzero((values[k, :-1] < 0) & (values[k, 1:] >= 0))
        if crossing.size:
            j = crossing[0]
            v0, v1 = values[k, j], values[k, j + 1]
            radii[k] = steps[j] + (steps[j + 1] - steps[j]) * v0 / (v0 - v1)
            slopes[k] = (v1 - v0) / (steps[j + 1] - steps[j])
    return radii, slopes


def _centres(density, labels, charges, cores) -> list[tuple[float, float]]:
    """Charge-weighted centre [cell-index units] of every labelled region.

    Plaquettes are shared between corner regions as for the charge; a topologically trivial bubble
    (|Q| < ½) falls back on its reversed core's centroid.
    """
    py, px = np.mgrid[0 : density.shape[0], 0 : density.shape[1]] + 0.5  # plaquette centres
    sum_x = topology.plaquette_sums(density * px, labels)
    sum_y = topology.plaquette_sums(density * py, labels)
    centres = []
    for k, charge in enumerate(charges):
        if abs(charge) > 0.5:
            centres.append((float(sum_x[k] / charge), float(sum_y[k] / charge)))
        else:
            cy, cx = ndimage.center_of_mass(cores == k + 1)
            centres.append((float(cx), float(cy)))
    return centres


def detect_skyrmions(
    field: xr.DataArray,
    threshold: float = 0.0,
    min_cells: int = 4,
    n_rays: int = 64,
    edge_band: bool = True,
) -> Snapshot:
    """Detect the skyrmions of one snapshot (see the module docstring for the method).

    ``edge_band=False`` keeps the film-edge band in the neighbourhoods: each centre is then the
    guiding centre of all the charge near its skyrmion (see "Two centres by an edge" in the
    module docstring).
    """
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
    if edge_band:
        band, width = find_edge_band(mz, magnetic, background, cores)
    else:
        band, width = np.zeros_like(magnetic), 0
    spline = ndimage.spline_filter(mz, order=3)
    dx, dy = float(field.attrs["dx"]), float(field.attrs["dy"])
    x0, y0 = float(field.x.values[0]), float(field.y.values[0])
    yy, xx = np.mgrid[0 : mz.shape[0], 0 : mz.shape[1]]  # cell-index units
    core_sizes = np.bincount(cores.ravel(), minlength=count + 1)
    neighbourhoods = np.zeros_like(regions)
    for label in range(1, count + 1):
        core = cores == label
        cy, cx = ndimage.center_of_mass(core)
        max_r = 2.0 * math.sqrt(core_sizes[label] / math.pi) + 3.0
        radii, slopes = _contour_rays(spline, background, cx, cy, max_r, n_rays)
        good = np.isfinite(radii)
        if good.any():
            reach = np.sqrt(np.mean(radii[good] ** 2)) + REACH_WALL_WIDTHS / np.median(slopes[good])
        else:  # no contour (a core at the threshold only): keep the whole Voronoi region
            reach = np.inf
        near = np.hypot(xx - cx, yy - cy) <= reach
        neighbourhoods[(regions == label) & near & ~band] = label
    charges = topology.topological_charge(field, neighbourhoods)
    dissipations = topology.dissipation(field, neighbourhoods)
    found = []
    centres = _centres(density, neighbourhoods, charges, cores)
    for label, (cx, cy) in enumerate(centres, start=1):
        max_r = 2.0 * math.sqrt(core_sizes[label] / math.pi) + 3.0
        radii, _ = _contour_rays(spline, background, cx, cy, max_r, n_rays)
        radii = radii * math.sqrt(dx * dy)
        good = radii[np.isfinite(radii)]
        radius = float(np.sqrt(np.mean(good**2))) if good.size else math.nan
        found.append(
            Skyrmion(
                x=x0 + cx * dx,
                y=y0 + cy * dy,
                radius=radius,
                charge=float(charges[label - 1]),
                dissipation=float(dissipations[label - 1]),
                area=float(core_sizes[label] * dx * dy),
                circularity=float(good.min() / good.max()) if good.size else math.nan,
                label=label,
            )
        )
    return Snapshot(tuple(found), neighbourhoods, total, time, width * math.sqrt(dx * dy))


def inspect_field(field: xr.DataArray, **options) -> dict:
    """A JSON-ready summary of one snapshot: per-skyrmion charge, centre, radius and 𝒟.

    Keys: ``skyrmions`` (objects with ``charge``, ``x_m``, ``y_m``, ``radius_m``,
    ``dissipation``, ``area_m2``, ``circularity``), ``total_charge``, ``time_s``,
    ``edge_band_width_m`` (the film-edge strip left out of every skyrmion), the mesh and the
    detection options.
    """
    snap = detect_skyrmions(field, **options)
    return {
        "skyrmions": [
            {
                "charge": s.charge,
                "x_m": s.x,
                "y_m": s.y,
                "radius_m": s.radius,
                "dissipation": s.dissipation,
                "area_m2": s.area,
                "circularity": s.circularity,
            }
            for s in snap.skyrmions
        ],
        "total_charge": snap.total_charge,
        "time_s": None if math.isnan(snap.time) else snap.time,
        "edge_band_width_m": snap.edge_band_width,
        "mesh": {
            "nx": field.sizes["x"],
            "ny": field.sizes["y"],
            "nz": field.sizes["z"],
            "dx_m": field.attrs["dx"],
            "dy_m": field.attrs["dy"],
            "dz_m": field.attrs["dz"],
        },
        "options": options,
        "skygas_version": __version__,
    }
