"""The candidate terms of a force model, sized from the tracks themselves.

Nothing here assumes what the skyrmions are: the landscape's resolution follows from the film's
size and how far a skyrmion moves in a frame, the pair law's range from the distances at which
neighbours are found, the wall law's range from the film's size. Which of the terms the data
actually show is decided later, by held-out likelihood (:mod:`skygas.inference.forces`).

- landscape: cubic B-splines :data:`LANDSCAPE_NODES` to the film's longer side (periodic in a
  periodic box), never closer than :data:`MIN_SPACING_STEPS` rms steps;
- pair: :data:`PAIR_FUNCTIONS` splines in ln r from the closest distances seen (the
  :data:`CLOSEST_QUANTILE` quantile of the nearest-neighbour distances) to
  :data:`PAIR_REACH` × the median nearest-neighbour distance;
- wall: :data:`WALL_FUNCTIONS` splines in ln d from the closest approach to the outline to
  :data:`WALL_REACH` × the film's inradius;
- drive: a uniform force, where the film is periodic or open (in a closed film a uniform force
  is a tilt of the landscape).
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from skygas.analysis.frames import Frames
from skygas.core.units import M_TO_NM
from skygas.inference.basis import Axis, LandscapeBasis, RadialBasis
from skygas.inference.film import Film
from skygas.inference.force_basis import ForceBasis, WallGeometry, neighbour_pairs

#: Landscape nodes along the film's longer side.
LANDSCAPE_NODES = 40
#: The landscape's nodes are at least this many rms steps per frame apart.
MIN_SPACING_STEPS = 1.0
#: Splines of the pair law and of the wall law.
PAIR_FUNCTIONS = 10
WALL_FUNCTIONS = 8
#: The pair law's closest distance: this quantile of the nearest-neighbour distances.
CLOSEST_QUANTILE = 0.005
#: The pair law ends at this many median nearest-neighbour distances ...
PAIR_REACH = 3.5
#: ... and at most at this share of the film's smaller side (periodic) or inradius.
PAIR_REACH_SHARE = 0.45
#: The wall law ends at this share of the film's inradius.
WALL_REACH = 0.3
#: Frames sampled to size the pair law.
SAMPLE_FRAMES = 500


def landscape_basis(film: Film, step: float) -> LandscapeBasis:
    """The landscape's splines over the film, ``step`` [m] the rms step per frame."""
    if film.periodic:
        assert film.period is not None
        lx, ly = film.period
        h = max(max(lx, ly) / LANDSCAPE_NODES, MIN_SPACING_STEPS * step)
        return LandscapeBasis(
            Axis.around(film.origin[0], lx, h), Axis.around(film.origin[1], ly, h)
        )
    x0, y0, x1, y1 = (v / M_TO_NM for v in film.outline.region.bounds)
    h = max(max(x1 - x0, y1 - y0) / LANDSCAPE_NODES, MIN_SPACING_STEPS * step)
    return LandscapeBasis(Axis.covering(x0, x1, h), Axis.covering(y0, y1, h))


def film_size(film: Film) -> float:
    """The film's smaller half-extent [m]: half the box's smaller side, or its inradius."""
    if film.periodic:
        assert film.period is not None
        return 0.5 * min(film.period)
    from skygas.inference.wall import inradius

    return inradius(film.outline)


def nearest_neighbour_distances(frames: Frames, film: Film, r_max: float) -> np.ndarray:
    """Each tracked position's distance to its nearest neighbour [m] (within r_max), sampled."""
    frames_sample = np.unique(np.linspace(0, frames.n_frames - 1, SAMPLE_FRAMES).astype(int))
    sub = frames.select(frames_sample)
    i, _, _, _, r = neighbour_pairs(sub, film, 0, sub.n_frames - 1, r_max)
    nn = np.full(len(sub.x), np.inf)
    np.minimum.at(nn, i, r)
    return nn[np.isfinite(nn)]


def pair_range(frames: Frames, film: Film) -> tuple[float, float] | None:
    """(closest, farthest) distance [m] of the pair law, or None (fewer than 2 per frame)."""
    if np.mean(frames.count) < 2:
        return None
    size = film_size(film)
    nn = nearest_neighbour_distances(frames, film, 2 * size)
    if len(nn) < 20:
        return None
    lo = float(np.quantile(nn, CLOSEST_QUANTILE))
    hi = min(PAIR_REACH * float(np.median(nn)), PAIR_REACH_SHARE * 2 * size)
    return (lo, hi) if hi > 1.5 * lo else None


def wall_range(frames: Frames, film: Film, geometry: WallGeometry) -> tuple[float, float]:
    """(closest, farthest) distance [m] of the wall law from the outline."""
    d, _, _ = geometry.at(*film.wrap(frames.x, frames.y))
    lo = max(float(np.quantile(d, 0.002)), 1e-3 * film_size(film))
    hi = WALL_REACH * film_size(film)
    return lo, max(hi, 2 * lo)


def build(
    frames: Frames,
    film: Film,
    step: float,
    *,
    pair: str,
    walls: str,
    material_law: Callable[[np.ndarray], np.ndarray] | None = None,
    material_range: float = 0.0,
) -> ForceBasis:
    """Every candidate term for these tracks.

    ``pair``: ``"none"``, ``"infer"`` (splines) or ``"material"`` (``material_law`` [k_BT/m]
    of r [m], acting to ``material_range``); ``walls``: ``"none"``, ``"infer"`` or
    ``"outline"`` (a wall term only where the film has walls).
    """
    land = landscape_basis(film, step)
    radial = None
    if pair == "infer":
        rng = pair_range(frames, film)
        if rng is not None:
            radial = RadialBasis(rng[0], rng[1], PAIR_FUNCTIONS, logarithmic=True)
    wall, geometry = None, None
    if walls != "none" and film.kind == "walls":
        geometry = WallGeometry.of(film, 0.25 * land.ax.spacing)
        lo, hi = wall_range(frames, film, geometry)
        wall = RadialBasis(lo, hi, WALL_FUNCTIONS, logarithmic=True)
    return ForceBasis(
        film,
        landscape=land,
        pair=radial,
        material_pair=material_law if pair == "material" else None,
        material_pair_range=material_range,
        wall=wall,
        wall_geometry=geometry,
        drive=film.kind in ("open", "periodic"),
    )
