"""Distance to the nearest wall and the inward wall normal, precomputed on a grid.

The engine needs, at every step and for every skyrmion, the distance d to the nearest wall and
the inward normal n̂ (the wall force is F_wall(d)·n̂). Computing them exactly with shapely is far
too slow inside a time loop, so :class:`WallField` samples them once on a uniform grid and the
kernels interpolate bilinearly.

What is stored (all nanometres):
- ``wall_distance``: distance to the nearest *wall* (ports are not walls), positive inside the
  device. Outside nodes are negative where their nearest boundary is a wall and positive where it
  is a port, so that interpolation is smooth across an open port.
- ``normal_x``, ``normal_y``: unit vector from the nearest wall point towards the node (inward).
- ``domain_distance``: signed distance to the whole boundary (walls and ports), positive inside;
  the engine uses it to notice a skyrmion that left the device.

Exact values are computed within ``band`` of the boundary (default: the wall-law cutoff plus two
cells); farther nodes take the Euclidean distance transform of the rasterised outline, and their
normals are zero (the wall force vanishes there anyway).

A field depends only on the outline, the spacing and the band, so each process builds it once per
combination and re-uses it (:mod:`skygas.core.memo`; its arrays are read-only).

Interpolation error
-------------------
Bilinear interpolation of a distance field is exact for straight walls. Against the outline
itself (a polygon) it errs by at most ~0.03 nm and 0.03 rad in the normal for the default
h = d_sk/16 ≈ 2.4 nm near a 512 nm disk, most of it at the polygon's corners. Circles are
polygons whose chords stray at most 0.05 nm inside the true circle
(:data:`skygas.physics.geometry._CHORD_ERROR_NM`), so against the ideal circle the distance is
within about 0.075 nm. The field is not smooth on the medial axis
(points equidistant from two walls, e.g. a conduit's centre line) and at concave corners; there
the interpolated normal blends the two walls' normals over one cell, so the wall force passes
continuously through the two walls' balance instead of jumping.
:meth:`WallField.interpolation_error` measures the error against shapely at random points;
``docs/engine.md`` quotes its output.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import shapely
from scipy import ndimage

from skygas.core.memo import Memo, frozen, outline_key
from skygas.core.resources import require_memory
from skygas.fields.nearest_segment import nearest_segment
from skygas.physics.geometry import Outline

# Wall fields built in this process, by outline, spacing and band (see skygas.core.memo): a sweep
# over current, p-value or temperature re-uses its device's field instead of rebuilding it.
_MEMO = Memo("wall_field", maxsize=4, persist=True)


@dataclass(frozen=True)
class BilinearWeights:
    """Where and with which weights to interpolate a (ny, nx) field at a set of points.

    Computing the weights once and applying them to several fields (or to the same field
    rescaled, as a sweep over current density does) gives exactly the bits of
    :func:`bilinear_at_indices`, which is this class applied once.
    """

    flat: np.ndarray  # index of the lower-left node in the raveled field
    nx: int
    w00: np.ndarray
    w10: np.ndarray
    w01: np.ndarray
    w11: np.ndarray

    @classmethod
    def at_indices(cls, shape: tuple[int, int], fx, fy) -> BilinearWeights:
        """Weights at fractional indices (fx, fy) of a field of ``shape`` (clamped to it)."""
        ny, nx = shape
        fx = np.clip(np.asarray(fx, float), 0, nx - 1 - 1e-9)
        fy = np.clip(np.asarray(fy, float), 0, ny - 1 - 1e-9)
        i = fx.astype(int)
        j = fy.astype(int)
        tx = fx - i
        ty = fy - j
        return cls(j * nx + i, nx, (1 - tx) * (1 - ty), tx * (1 - ty), (1 - tx) * ty, tx * ty)

    def apply(self, field: np.ndarray) -> np.ndarray:
        """The interpolated values of ``field`` (same arithmetic as the kernels)."""
        f = field.reshape(-1)
        k = self.flat
        return (
            self.w00 * f[k]
            + self.w10 * f[k + 1]
            + self.w01 * f[k + self.nx]
            + self.w11 * f[k + self.nx + 1]
        )


def bilinear_at_indices(field: np.ndarray, fx, fy) -> np.ndarray:
    """Bilinear interpolation of ``field`` (ny, nx) at fractional indices (fx, fy).

    Clamped to the grid; the same arithmetic as the kernels.
    """
    return BilinearWeights.at_indices(field.shape, fx, fy).apply(field)


@dataclass(frozen=True)
class Grid:
    """A uniform grid: node (i, j) sits at (x0 + i·spacing, y0 + j·spacing) nm."""

    x0: float
    y0: float
    spacing: float
    nx: int
    ny: int

    def nodes(self) -> tuple[np.ndarray, np.ndarray]:
        """The coordinates x, y [nm] of every node, arrays of shape (ny, nx)."""
        x = self.x0 + self.spacing * np.arange(self.nx)
        y = self.y0 + self.spacing * np.arange(self.ny)
        return np.meshgrid(x, y)  # arrays of shape (ny, nx)

    def bilinear(self, field: np.ndarray, x, y) -> np.ndarray:
        """Bilinear interpolation of ``field`` (ny, nx) at (x, y) nm, as the kernels do."""
        return bilinear_at_indices(
            field,
            (np.asarray(x, float) - self.x0) / self.spacing,
            (np.asarray(y, float) - self.y0) / self.spacing,
        )


def _segments(lines) -> np.ndarray:
    """All straight segments of a (Multi)LineString as an (n, 4) array x1, y1, x2, y2."""
    parts = getattr(lines, "geoms", [lines])
    segs = []
    for part in parts:
        c = np.asarray(part.coords)
        if len(c) >= 2:
            segs.append(np.hstack([c[:-1], c[1:]]))
    return np.vstack(segs) if segs else np.empty((0, 4))


@dataclass(frozen=True)
class WallField:
    """Wall distance, inward normal and domain distance sampled on :attr:`grid` (nm)."""

    grid: Grid
    wall_distance: np.ndarray
    normal_x: np.ndarray
    normal_y: np.ndarray
    domain_distance: np.ndarray
    band: float

    @classmethod
    def build(cls, outline: Outline, spacing: float, band: float) -> WallField:
        """Sample ``outline`` with grid ``spacing`` [nm]; exact within ``band`` [nm].

        The field depends only on these three, so it is built once per process for each
        (outline, spacing, band) and shared, read-only, by later calls (:mod:`skygas.core.memo`).
        """
        return _MEMO.get(
            cls.key(outline, spacing, band),
            lambda: cls._build(outline, float(spacing), float(band)),
        )

    @staticmethod
    def key(outline: Outline, spacing: float, band: float) -> tuple:
        """The memo key of the field :meth:`build` makes (and of what is derived from it alone)."""
        return (outline_key(outline), float(spacing), float(band))

    @classmethod
    def _build(cls, outline: Outline, spacing: float, band: float) -> WallField:
        x0, y0, x1, y1 = outline._bounds_nm
        margin = 3 * spacing
        nx = int(np.ceil((x1 - x0 + 2 * margin) / spacing)) + 1
        ny = int(np.ceil((y1 - y0 + 2 * margin) / spacing)) + 1
        # the distances, the normals and the scratch of the distance transform: about ten
        # float64 values per node
        require_memory(
            "geometry",
            f"an outline of {x1 - x0:.3g} nm × {y1 - y0:.3g} nm",
            80.0 * nx * ny,
            f"its wall grid of {nx} × {ny} nodes at {spacing:g} nm",
            "lengths are in metres: did you mean nanometres?",
        )
        grid = Grid(x0 - margin, y0 - margin, float(spacing), nx, ny)
        gx, gy = grid.nodes()
        inside = outline._contains_nm(gx, gy)

        # Approximate distance everywhere (Euclidean distance transform of the raster) ...
        approx = (
            np.where(
                inside,
                ndimage.distance_transform_edt(inside),
                -ndimage.distance_transform_edt(~inside),
            )
            * spacing
        )
        wall_distance = approx.copy()
        domain_distance = approx.copy()
        normal_x = np.zeros_like(approx)
        normal_y = np.zeros_like(approx)

        # ... and exact values near the boundary (bucketed exact search:
        # skygas.fields.nearest_segment).
        near = np.abs(approx) < band + 2 * spacing
        px, py = gx[near], gy[near]
        wall_segs = _segments(outline.walls)
        dist, qx, qy, index = nearest_segment(px, py, wall_segs)
        is_inside = inside[near]
        sign = np.where(is_inside, 1.0, -1.0)
        boundary_dist = dist
        if outline.ports:
            port_segs = np.vstack([_segments(p) for p in outline.ports.values()])
            port_dist = nearest_segment(px, py, port_segs)[0]
            boundary_dist = np.minimum(dist, port_dist)
            # Outside nodes whose nearest boundary is a port lie beyond an opening: positive.
            sign = np.where(~is_inside & (port_dist < dist - 1e-9), 1.0, sign)
        with np.errstate(invalid="ignore", divide="ignore"):
            nxv = np.where(dist > 1e-9, (px - qx) / dist, 0.0)
            nyv = np.where(dist > 1e-9, (py - qy) / dist, 0.0)
        # Nodes exactly on a wall: use the segment's perpendicular, oriented inwards.
        on_wall = dist <= 1e-9
        if np.any(on_wall):
            ax, ay, bx, by = wall_segs[index[on_wall]].T
            length = np.hypot(bx - ax, by - ay)
            cx, cy = -(by - ay) / length, (bx - ax) / length
            probe_in = outline._contains_nm(
                px[on_wall] + 1e-3 * spacing * cx, py[on_wall] + 1e-3 * spacing * cy
            )
            flip = np.where(probe_in, 1.0, -1.0)
            nxv[on_wall], nyv[on_wall] = flip * cx, flip * cy
        # outside, beyond a wall: the normal points back in (nodes on a wall already do)
        outward = ~is_inside & (sign < 0) & ~on_wall
        nxv = np.where(outward, -nxv, nxv)
        nyv = np.where(outward, -nyv, nyv)
        wall_distance[near] = sign * dist
        domain_distance[near] = np.where(is_inside, 1.0, -1.0) * boundary_dist
        normal_x[near] = nxv
        normal_y[near] = nyv
        frozen(wall_distance, normal_x, normal_y, domain_distance)
        return cls(grid, wall_distance, normal_x, normal_y, domain_distance, float(band))

    def interpolate(self, x, y) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Interpolated (wall distance, normal x, normal y) at (x, y) nm."""
        g = self.grid
        return (
            g.bilinear(self.wall_distance, x, y),
            g.bilinear(self.normal_x, x, y),
            g.bilinear(self.normal_y, x, y),
        )

    def interpolation_error(
        self, outline: Outline, n_samples: int = 20_000, seed: int = 0
    ) -> dict[str, float]:
        """Error of the interpolated wall distance [nm] and normal [rad] against shapely.

        At random inside points within ``band`` of a wall (quantiles and maximum).
        """
        rng = np.random.default_rng(seed)
        x0, y0, x1, y1 = outline._bounds_nm
        pts = rng.uniform((x0, y0), (x1, y1), size=(20 * n_samples, 2))
        pts = pts[outline._contains_nm(pts[:, 0], pts[:, 1])]
        exact = outline._wall_distance_nm(pts[:, 0], pts[:, 1])
        keep = exact < self.band
        pts, exact = pts[keep][:n_samples], exact[keep][:n_samples]
        d, nx, ny = self.interpolate(pts[:, 0], pts[:, 1])
        points = shapely.points(pts[:, 0], pts[:, 1])
        nearest = shapely.get_coordinates(shapely.shortest_line(points, outline.walls))[1::2]
        ex = (pts - nearest) / np.maximum(exact, 1e-12)[:, None]
        angle = np.abs(np.arctan2(ex[:, 0] * ny - ex[:, 1] * nx, ex[:, 0] * nx + ex[:, 1] * ny))
        err = np.abs(d - exact)
        return {
            "samples": int(len(err)),
            "distance_error_median_nm": float(np.median(err)),
            "distance_error_p99_nm": float(np.quantile(err, 0.99)),
            "distance_error_max_nm": float(err.max()),
            "normal_error_median_rad": float(np.median(angle)),
            "normal_error_p99_rad": float(np.quantile(angle, 0.99)),
            "normal_error_max_rad": float(angle.max()),
        }
