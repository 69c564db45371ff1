"""The inferred landscape on a grid: its value, its error, where the data fix it, its statistics.

U(x, y) [k_BT] is the landscape term of the force model (:mod:`skygas.inference.forces`)
evaluated on the nodes of a grid over the film, defined up to a constant. Its error is the
larger of two jackknifes: over blocks of time and over groups of tracks (where skyrmions sit
in their wells all movie long, every block of time sees the same skyrmion in a well, and only
leaving that skyrmion out shows how much the map there rests on it). An error of U needs a
reference: the map's constant is set by
U's mean over the **well-sampled** area, and that area is where the error, so referenced, is at
most :data:`WELL_SAMPLED_ERROR` k_BT and a node's neighbourhood (one spline spacing) holds at
least :data:`MIN_POSITIONS` tracked positions. The two depend on each other, so the area is
found by iteration: start from every sampled node, compute the errors relative to the area's
mean, keep the nodes within the bound, repeat until the area stops changing
(:func:`well_sampled`). The result is a map fixed to the bound *up to a constant* over that
area, which is what a pinning landscape is.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy import ndimage

from skygas.analysis.frames import Frames
from skygas.inference.forces import ForceInference, jackknife_error
from skygas.inference.landscape import Grid, correlation_length, deepest_wells, make_grid

#: A node is well sampled where U's jackknife error, relative to the area's mean, is at most
#: this [k_BT] ...
WELL_SAMPLED_ERROR = 0.25
#: ... and at least this many positions lie within one spline spacing of it.
MIN_POSITIONS = 20
#: Iterations of the well-sampled area at most.
AREA_ITERATIONS = 10


@dataclass(frozen=True)
class ForceMap:
    """U [k_BT] on ``grid`` (NaN off the film) with its jackknife ``error`` on ``well_sampled``.

    ``replicas``: one (B, ny, nx) array of leave-one-out maps per jackknife (blocks of time,
    and groups of tracks where there are enough); ``sampled`` the nodes with enough
    positions nearby; ``film`` the nodes on the film.
    """

    grid: Grid
    u: np.ndarray
    error: np.ndarray
    well_sampled: np.ndarray
    sampled: np.ndarray
    film: np.ndarray
    replicas: tuple[np.ndarray, ...]


def landscape_on_grid(result: ForceInference, x: np.ndarray, y: np.ndarray, fit=None):
    """U [k_BT] of ``fit`` (default: the final one) on x × y (zeros without a landscape)."""
    basis = result.basis
    if basis.landscape is None or "landscape" not in result.terms:
        return np.zeros((len(y), len(x)))
    return basis.landscape.grid(x, y, result.coefficients("landscape", fit))


def sampled_nodes(frames: Frames, grid: Grid, film, spacing: float) -> np.ndarray:
    """Nodes with at least :data:`MIN_POSITIONS` positions within ``spacing`` [m] (a box)."""
    x, y = film.wrap(frames.x, frames.y)
    counts = grid.bins(x, y)
    size = max(1, int(round(2 * spacing / grid.h)) | 1)
    near = ndimage.uniform_filter(counts, size=size, mode="wrap" if film.periodic else "constant")
    return near * size * size >= MIN_POSITIONS


def well_sampled(replicas, start: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(the well-sampled mask, the error of U relative to its mean over it) from the replicas.

    ``replicas``: a sequence of (B, ny, nx) arrays, one per jackknife; the larger error is taken.

    Iterated from ``start`` (see the module's text); the error is NaN off ``start``.
    """
    area = start.copy()
    error = np.full(start.shape, np.nan)
    for _ in range(AREA_ITERATIONS):
        if not area.any():
            break
        error = np.max(
            [
                jackknife_error(reps - reps[:, area].mean(axis=1)[:, None, None])
                for reps in replicas
            ],
            axis=0,
        )
        error = np.where(start, error, np.nan)
        with np.errstate(invalid="ignore"):
            new = start & (error <= WELL_SAMPLED_ERROR)
        if np.array_equal(new, area):
            break
        area = new
    with np.errstate(invalid="ignore"):
        return start & (error <= WELL_SAMPLED_ERROR), error


def force_map(result: ForceInference, frames: Frames, spacing: float) -> ForceMap:
    """The landscape of ``result`` on a grid of ``spacing`` [m] over the film, with its errors."""
    film = result.basis.film
    grid = make_grid(film.outline, spacing)
    on_film = grid.inside > 0
    u = landscape_on_grid(result, grid.x, grid.y)
    replicas = tuple(
        np.array([landscape_on_grid(result, grid.x, grid.y, f) for f in reps])
        for reps in result.replica_sets
    )
    h = result.basis.landscape.ax.spacing if result.basis.landscape is not None else spacing
    sampled = on_film & sampled_nodes(frames, grid, film, h)
    well, error = well_sampled(replicas, sampled)
    if well.any():
        u = u - u[well].mean()
    elif sampled.any():
        u = u - u[sampled].mean()
    u = np.where(on_film, u, np.nan)
    return ForceMap(grid, u, error, well, sampled, on_film, replicas)


def statistics(fmap: ForceMap, interior: np.ndarray | None = None) -> dict:
    """The pinning's rms and correlation length over the well-sampled area, and its wells.

    ``interior``: a mask the statistics are further restricted to (e.g. away from a wall).
    The rms is quoted with its jackknife error; ξ is where the autocorrelation falls to e^(−½)
    (:func:`~skygas.inference.landscape.correlation_length`).
    """
    area = fmap.well_sampled if interior is None else fmap.well_sampled & interior
    if area.sum() < 4:
        return {"rms_kT": None, "rms_error_kT": None, "correlation_length_m": None, "wells": []}
    rms, xi = correlation_length(np.nan_to_num(fmap.u), area, fmap.grid.h)
    rms_err = max(
        float(jackknife_error(np.array([np.std(r[area] - r[area].mean()) for r in reps])))
        for reps in fmap.replicas
    )
    radius = 0.5 * xi if math.isfinite(xi) else 2 * fmap.grid.h
    wells = [
        {"x_m": x, "y_m": y, "depth_kT": depth}
        for x, y, depth in deepest_wells(fmap.u, area, fmap.grid, radius)
    ]
    return {
        "rms_kT": rms,
        "rms_error_kT": rms_err,
        "correlation_length_m": xi if math.isfinite(xi) else None,
        "wells": wells,
    }
