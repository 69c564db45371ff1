"""The film's edge: distances to it, and the wall potential read off the density (a cross-check).

:func:`wall_distance` and :func:`inradius` are the geometry every part of the inference uses.
:func:`wall_profile` is the equilibrium cross-check of the wall force the steps show
(:mod:`skygas.inference.forces`): positions are binned by their distance d to the outline's
boundary (shapely); each bin's density is its share of positions over the area of the band of
the film at that distance (the exact area between the outline shrunk by d₁ and by d₂), so the
geometry does not enter, and

    W(d) = −k_BT ln(ρ(d) / ρ_bulk),

with ρ_bulk the density beyond :data:`BULK_FRACTION` of the film's inradius. Errors are blocked
over contiguous blocks of time. In a gas W(d) also carries the neighbours' layering against the
wall (:mod:`skygas.inference.crowding` takes their mean push out).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from skygas.analysis.frames import Frames
from skygas.core.units import M_TO_NM
from skygas.inference.diffusion import blocked, time_blocks
from skygas.physics.geometry import Outline

#: The bulk starts at this fraction of the film's inradius from the boundary.
BULK_FRACTION = 0.5
#: Blocks of time for the errors.
BLOCKS = 16


@dataclass(frozen=True)
class WallProfile:
    """W(d) [k_BT] ± ``error`` at bin centres ``d`` [m] with ``counts`` positions per bin.

    ``bulk_from`` [m] where the bulk starts.
    """

    d: np.ndarray
    w: np.ndarray
    error: np.ndarray
    counts: np.ndarray
    bulk_from: float


def wall_distance(outline: Outline, x: np.ndarray, y: np.ndarray) -> np.ndarray:
    """Distance [m] of each point to the outline's boundary (negative outside)."""
    x, y = np.asarray(x, float), np.asarray(y, float)
    d = np.asarray(outline.wall_distance(x, y))
    return np.where(outline.contains(x, y), d, -d)


def inradius(outline: Outline) -> float:
    """The largest distance [m] from the boundary inside the outline.

    Shapely's largest inscribed circle, to 0.1 % of the outline's size.
    """
    import shapely

    region = outline.region
    size = max(region.bounds[2] - region.bounds[0], region.bounds[3] - region.bounds[1])
    parts = getattr(region, "geoms", [region])
    radius = max(
        shapely.maximum_inscribed_circle(part, tolerance=1e-3 * size).length for part in parts
    )
    return float(radius) / M_TO_NM


def wall_profile(
    frames: Frames, outline: Outline, bin_width: float, normal_force: np.ndarray | None = None
) -> WallProfile:
    """W(d) of the tracks in ``outline``, binned by ``bin_width`` [m], with blocked errors.

    ``normal_force`` (E,) [k_BT/m]: the neighbours' pair force on each entry along the inward
    normal (:func:`skygas.inference.crowding.normal_component`). Given, their mean push is taken
    out by force balance: W(d) = −ln(ρ(d)/ρ_bulk) − ∫_d^bulk f̄_n(s) ds, with f̄_n the mean normal
    force on the skyrmions at distance s (without it a crowded gas pressed against the wall
    reads a wall softer than it is).
    """
    from skygas.inference.landscape import make_grid

    reach = inradius(outline)
    edges = np.arange(0.0, reach + bin_width, bin_width)
    # the area of each band of distance to the edge, from a grid four times finer than the bins
    grid = make_grid(outline, bin_width / 4)
    gx, gy = np.meshgrid(grid.x, grid.y)
    node_d = wall_distance(outline, gx, gy)
    band_area = np.histogram(node_d, edges, weights=grid.inside * grid.h**2)[0]
    d = wall_distance(outline, frames.x, frames.y)
    bulk_from = BULK_FRACTION * reach
    bulk = edges[:-1] >= bulk_from

    inner = np.flatnonzero(~bulk)

    def profile(sel):
        dd = np.clip(d[sel], 0, None)
        counts = np.histogram(dd, edges)[0].astype(float)
        with np.errstate(divide="ignore", invalid="ignore"):
            rho = counts / band_area
            rho_bulk = counts[bulk].sum() / band_area[bulk].sum()
            w = -np.log(rho / rho_bulk)
            if normal_force is not None:
                push = np.histogram(dd, edges, weights=normal_force[sel])[0]
                mean = np.where(counts > 0, push / np.maximum(counts, 1), 0.0)
                # ∫ from each bin's centre to the start of the bulk
                tail = np.cumsum(mean[inner][::-1])[::-1]
                w[inner] -= bin_width * (tail - 0.5 * mean[inner])
            return w, counts

    w, counts = profile(np.ones(len(d), bool))
    frame = frames.frame_of_entry
    per_block = []
    for b in time_blocks(frames.n_frames, BLOCKS):
        per_block.append(profile((frame >= b[0]) & (frame <= b[-1]))[0])
    per_block_arr = np.array(per_block)
    error = np.array(
        [blocked(per_block_arr[:, k]) if np.isfinite(w[k]) else np.inf for k in range(len(w))]
    )
    centres = 0.5 * (edges[1:] + edges[:-1])
    return WallProfile(centres, w, error, counts, bulk_from)
