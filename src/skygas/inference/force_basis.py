"""The force on a tracked skyrmion as a sum of basis fields: landscape, pair, wall, drive.

f(xᵢ) = −∇U(xᵢ) + Σⱼ f_pair(rᵢⱼ) r̂ᵢⱼ + f_wall(d(xᵢ)) n̂(xᵢ) + f_drive       [k_BT/m]

with U, f_pair and f_wall expanded in the B-splines of :mod:`skygas.inference.basis` and the
drive a uniform force. :class:`ForceBasis` holds which terms a model has and where their
coefficients sit in the one vector θ, and evaluates the fields g_k (and their divergences) at
tracked positions: the pair fields from each skyrmion's neighbours in the same frame
(:func:`neighbour_pairs`), the wall fields from the distance to the outline
(:class:`WallGeometry`).

The base material's own pair law can stand in for a fitted one (``material_pair``): one column
whose coefficient scales that law.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np
from scipy import sparse
from scipy.interpolate import RegularGridInterpolator
from scipy.spatial import cKDTree

from skygas.analysis.frames import Frames
from skygas.inference.basis import Fields, LandscapeBasis, RadialBasis
from skygas.inference.film import Film

#: The terms a model may have, in the order of their columns.
TERMS = ("landscape", "pair", "material_pair", "wall", "drive")
#: Largest number of nodes a side of the wall-distance grid.
WALL_GRID_NODES = 800


def neighbour_pairs(
    frames: Frames, film: Film, first: int, last: int, r_max: float
) -> tuple[np.ndarray, ...]:
    """Ordered pairs (i, j) of entries in the same frame, first ≤ frame ≤ last, closer than r_max.

    Returns i, j (entries, both orders), dx, dy = xᵢ − xⱼ by the minimum image [m] and r [m].
    One k-d tree holds every frame, the frame number as a third coordinate far apart, and is
    searched in the maximum norm (then the Euclidean distance is checked).
    """
    off = frames.offsets
    e0, e1 = int(off[first]), int(off[last + 1])
    empty = np.zeros(0, np.int64)
    if e1 - e0 < 2 or not np.isfinite(r_max) or r_max <= 0:
        return empty, empty, np.zeros(0), np.zeros(0), np.zeros(0)
    x, y = frames.x[e0:e1], frames.y[e0:e1]
    if film.periodic:
        x, y = film.wrap(x, y)
    f = frames.frame_of_entry[e0:e1] - first
    gap = 4.0 * r_max + 10.0 * max(float(np.ptp(x)), float(np.ptp(y)), r_max)
    points = np.column_stack([x, y, f * gap])
    if film.periodic:
        assert film.period is not None
        lx, ly = film.period
        px = np.mod(x - film.origin[0], lx)
        py = np.mod(y - film.origin[1], ly)
        points = np.column_stack([px, py, f * gap])
        tree = cKDTree(points, boxsize=[lx, ly, gap * (last - first + 2)])
    else:
        tree = cKDTree(points)
    pairs = tree.query_pairs(r_max, p=np.inf, output_type="ndarray")
    i, j = pairs[:, 0], pairs[:, 1]
    dx, dy = film.separation(x[i] - x[j], y[i] - y[j])
    r = np.hypot(dx, dy)
    keep = (r < r_max) & (r > 0)
    i, j, dx, dy, r = i[keep], j[keep], dx[keep], dy[keep], r[keep]
    return (
        np.concatenate([i, j]) + e0,
        np.concatenate([j, i]) + e0,
        np.concatenate([dx, -dx]),
        np.concatenate([dy, -dy]),
        np.concatenate([r, r]),
    )


@dataclass(frozen=True)
class WallGeometry:
    """The distance d [m] to the outline and the inward normal n̂ = ∇d, interpolated on a grid."""

    distance: RegularGridInterpolator
    nx: RegularGridInterpolator
    ny: RegularGridInterpolator

    @classmethod
    def of(cls, film: Film, spacing: float) -> WallGeometry:
        """The grid over the outline's bounds, ``spacing`` [m] apart at most (≤ 800 a side)."""
        from skygas.core.units import M_TO_NM
        from skygas.inference.wall import wall_distance

        x0, y0, x1, y1 = (v / M_TO_NM for v in film.outline.region.bounds)
        h = max(spacing, max(x1 - x0, y1 - y0) / WALL_GRID_NODES)
        xs = np.arange(x0 - 2 * h, x1 + 2.5 * h, h)
        ys = np.arange(y0 - 2 * h, y1 + 2.5 * h, h)
        gx, gy = np.meshgrid(xs, ys)
        d = wall_distance(film.outline, gx, gy)
        ny_, nx_ = np.gradient(d, h)
        norm = np.maximum(np.hypot(nx_, ny_), 1e-12)

        def interp(values):
            return RegularGridInterpolator((ys, xs), values, bounds_error=False, fill_value=None)

        return cls(interp(d), interp(nx_ / norm), interp(ny_ / norm))

    def at(self, x: np.ndarray, y: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(d, n̂_x, n̂_y) at the points."""
        p = np.column_stack([y, x])
        nx_, ny_ = self.nx(p), self.ny(p)
        norm = np.maximum(np.hypot(nx_, ny_), 1e-12)
        return self.distance(p), nx_ / norm, ny_ / norm


@dataclass(frozen=True)
class ForceBasis:
    """The terms of a force model and their columns in θ.

    ``landscape`` U's splines; ``pair`` the fitted pair law's splines in r; ``material_pair``
    the base material's law f(r) [k_BT/m] (one column that scales it); ``wall`` the wall law's
    splines in d with the outline's :class:`WallGeometry` ``wall_geometry``; ``drive`` a uniform
    force (two columns). Terms set to None (False) are absent.
    """

    film: Film
    landscape: LandscapeBasis | None = None
    pair: RadialBasis | None = None
    material_pair: Callable[[np.ndarray], np.ndarray] | None = None
    material_pair_range: float = 0.0
    wall: RadialBasis | None = None
    wall_geometry: WallGeometry | None = None
    drive: bool = False
    columns: dict = field(default_factory=dict, init=False, compare=False)

    def __post_init__(self):
        k = 0
        sizes = {
            "landscape": self.landscape.size if self.landscape else 0,
            "pair": self.pair.size if self.pair else 0,
            "material_pair": 1 if self.material_pair is not None else 0,
            "wall": self.wall.size if self.wall else 0,
            "drive": 2 if self.drive else 0,
        }
        for name in TERMS:
            self.columns[name] = slice(k, k + sizes[name])
            k += sizes[name]

    @property
    def size(self) -> int:
        """The number of coefficients K."""
        return max(s.stop for s in self.columns.values())

    def has(self, term: str) -> bool:
        """Whether the model has ``term``."""
        s = self.columns[term]
        return s.stop > s.start

    def indices(self, terms) -> np.ndarray:
        """The columns of ``terms``."""
        return np.concatenate(
            [np.arange(self.columns[t].start, self.columns[t].stop) for t in terms]
            or [np.zeros(0, np.int64)]
        ).astype(np.int64)

    @property
    def pair_range(self) -> float:
        """The largest distance [m] at which a pair term acts (0 without one)."""
        r = self.pair.hi if self.pair is not None else 0.0
        return max(r, self.material_pair_range if self.material_pair is not None else 0.0)

    def fields(self, frames: Frames, entries: np.ndarray, pairs) -> Fields:
        """g_k and ∇·g_k at ``entries`` (sorted); ``pairs`` from :func:`neighbour_pairs`.

        ``pairs`` must hold every neighbour within :attr:`pair_range` of each entry.
        """
        n = len(entries)
        x, y = self.film.wrap(frames.x[entries], frames.y[entries])
        parts = []
        if self.landscape is not None:
            parts.append(self.landscape.fields(x, y))
        if self.pair is not None or self.material_pair is not None:
            i, _, dx, dy, r = pairs
            row = np.searchsorted(entries, i)
            ok = (row < n) & (entries[np.minimum(row, n - 1)] == i)
            row, dx, dy, r = row[ok], dx[ok], dy[ok], r[ok]
            if self.pair is not None:
                parts.append(_radial_sum(self.pair, row, dx, dy, r, n))
            if self.material_pair is not None:
                f = np.asarray(self.material_pair(r), float)
                # ∇·(f(r) r̂) = f′(r) + f/r, f′ by a central difference
                h = 1e-3 * np.maximum(r, 1e-12)
                slope = (
                    np.asarray(self.material_pair(r + h), float)
                    - np.asarray(self.material_pair(r - h), float)
                ) / (2 * h)
                parts.append(
                    _columns(
                        n,
                        np.bincount(row, f * dx / r, n)[:, None],
                        np.bincount(row, f * dy / r, n)[:, None],
                        np.bincount(row, slope + f / r, n)[:, None],
                    )
                )
        if self.wall is not None:
            assert self.wall_geometry is not None
            d, nx_, ny_ = self.wall_geometry.at(x, y)
            psi, slope = self.wall.evaluate(np.maximum(d, 0.0))
            parts.append(_columns(n, psi * nx_[:, None], psi * ny_[:, None], slope))
        if self.drive:
            ones, zeros = np.ones((n, 1)), np.zeros((n, 1))
            parts.append(
                _columns(n, np.hstack([ones, zeros]), np.hstack([zeros, ones]), np.zeros((n, 2)))
            )
        if not parts:
            return _columns(n, np.zeros((n, 0)), np.zeros((n, 0)), np.zeros((n, 0)))
        return Fields.stack(parts)


def _columns(n: int, gx, gy, div) -> Fields:
    return Fields(*(sparse.csr_matrix(np.asarray(a, float).reshape(n, -1)) for a in (gx, gy, div)))


def _radial_sum(basis: RadialBasis, row, dx, dy, r, n: int) -> Fields:
    """Σⱼ ψ_k(rᵢⱼ) r̂ᵢⱼ and its divergence Σⱼ ψ′_k + ψ_k/r per entry row."""
    inside = r < basis.hi
    row, dx, dy, r = row[inside], dx[inside], dy[inside], r[inside]
    psi, slope = basis.evaluate(r)
    k = basis.size
    gx = np.zeros((n, k))
    gy = np.zeros((n, k))
    div = np.zeros((n, k))
    for c in range(k):
        gx[:, c] = np.bincount(row, psi[:, c] * dx / r, n)
        gy[:, c] = np.bincount(row, psi[:, c] * dy / r, n)
        div[:, c] = np.bincount(row, slope[:, c] + psi[:, c] / r, n)
    return _columns(n, gx, gy, div)
