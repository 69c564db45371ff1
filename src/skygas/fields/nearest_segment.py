"""Exact nearest point on a set of line segments, for many query points (wall-field set-up).

:class:`~skygas.fields.wall_field.WallField` needs, for every grid node near the boundary, the exact
nearest wall point. The 1024 nm reshuffler has ~560 wall segments and ~4×10⁵ such nodes (the
wall force reaches ~260 nm); the brute-force scan over all segments
(:func:`nearest_segment_brute`, kept as the reference) took 1-1.5 s of every run's set-up.
:func:`nearest_segment` gives the *same bits* about 9× faster by bucketing the segments into
square cells and searching rings of cells around each point, outwards, only until no unvisited
cell can hold a closer segment; cells farther than the best segment so far are skipped, and the
previous point's winner (grid nodes come in raster order) gives a tight first bound.

Why the results are bit-identical to the brute-force scan: each candidate segment is evaluated
with the same arithmetic, and ties (equal squared distances) go to the lowest segment index,
exactly as the in-order scan with a strict ``<`` keeps the first. A cell is skipped only when its
distance from the point exceeds the best distance found (with a relative margin of 1e-9 that
covers rounding), so every segment that could win or tie is evaluated.
"""

from __future__ import annotations

import math

import numba
import numpy as np

# below this many segments the scan is as fast as bucketing
_BRUTE_FORCE_BELOW = 32
# a cell is searched unless (ring distance)² · (1 − margin) exceeds the best squared distance
_MARGIN = 1e-9


@numba.njit(cache=True)
def _point_to_segment(x, y, segs, n):
    """Nearest point on segment ``n`` and its squared distance (the reference arithmetic)."""
    ax, ay, bx, by = segs[n, 0], segs[n, 1], segs[n, 2], segs[n, 3]
    dx, dy = bx - ax, by - ay
    t = ((x - ax) * dx + (y - ay) * dy) / max(dx * dx + dy * dy, 1e-300)
    t = min(max(t, 0.0), 1.0)
    qx, qy = ax + t * dx, ay + t * dy
    return (x - qx) ** 2 + (y - qy) ** 2, qx, qy


@numba.njit(cache=True)
def _brute_kernel(px, py, segs, out_d, out_x, out_y, out_i):
    for p in range(px.shape[0]):
        best = np.inf
        for n in range(segs.shape[0]):
            d2, qx, qy = _point_to_segment(px[p], py[p], segs, n)
            if d2 < best:
                best = d2
                out_x[p], out_y[p], out_i[p] = qx, qy, n
        out_d[p] = np.sqrt(best)


@numba.njit(cache=True)
def _bucket(segs, x0, y0, cell, ncx, ncy):
    """Cells → segments (CSR: ``start`` offsets into ``members``).

    A segment is listed in every cell its bounding box overlaps.
    """
    n = segs.shape[0]
    lo_i = np.empty(n, np.int64)
    hi_i = np.empty(n, np.int64)
    lo_j = np.empty(n, np.int64)
    hi_j = np.empty(n, np.int64)
    count = np.zeros(ncx * ncy + 1, np.int64)
    for s in range(n):
        xa, xb = min(segs[s, 0], segs[s, 2]), max(segs[s, 0], segs[s, 2])
        ya, yb = min(segs[s, 1], segs[s, 3]), max(segs[s, 1], segs[s, 3])
        lo_i[s] = min(max(int(math.floor((xa - x0) / cell)), 0), ncx - 1)
        hi_i[s] = min(max(int(math.floor((xb - x0) / cell)), 0), ncx - 1)
        lo_j[s] = min(max(int(math.floor((ya - y0) / cell)), 0), ncy - 1)
        hi_j[s] = min(max(int(math.floor((yb - y0) / cell)), 0), ncy - 1)
        for j in range(lo_j[s], hi_j[s] + 1):
            for i in range(lo_i[s], hi_i[s] + 1):
                count[j * ncx + i + 1] += 1
    start = np.cumsum(count)
    fill = start[:-1].copy()
    members = np.empty(start[-1], np.int64)
    for s in range(n):
        for j in range(lo_j[s], hi_j[s] + 1):
            for i in range(lo_i[s], hi_i[s] + 1):
                members[fill[j * ncx + i]] = s
                fill[j * ncx + i] += 1
    return start, members


@numba.njit(cache=True)
def _scan_cell(x, y, segs, start, members, c, best, best_n, bx, by):
    """Evaluate the segments listed in cell ``c``; keep the nearest (ties: lowest index)."""
    for k in range(start[c], start[c + 1]):
        n = members[k]
        d2, qx, qy = _point_to_segment(x, y, segs, n)
        if d2 < best or (d2 == best and n < best_n):
            best, best_n, bx, by = d2, n, qx, qy
    return best, best_n, bx, by


@numba.njit(cache=True)
def _grid_kernel(px, py, segs, x0, y0, cell, ncx, ncy, start, members, out_d, out_x, out_y, out_i):
    tol = 1e-6 * cell  # cell bounds are grown by this, to cover rounding in the bucketing
    best_n = -1
    for p in range(px.shape[0]):
        x, y = px[p], py[p]
        ci = int(math.floor((x - x0) / cell))
        cj = int(math.floor((y - y0) / cell))
        # rings beyond this one hold no cells
        last = max(max(ci, ncx - 1 - ci), max(cj, ncy - 1 - cj))
        best, bx, by = np.inf, 0.0, 0.0
        if best_n >= 0:  # the previous point's winner (usually a neighbour): a tight bound
            best, bx, by = _point_to_segment(x, y, segs, best_n)
        for r in range(last + 1):
            # the ring of cells r away (Chebyshev) from the point's cell, clipped to the grid
            for j in range(max(cj - r, 0), min(cj + r, ncy - 1) + 1):
                gy = max(max(y0 + j * cell - tol - y, y - (y0 + (j + 1) * cell + tol)), 0.0)
                # whole rows on the ring's top and bottom, only its two ends in between
                step = 1 if (j == cj - r or j == cj + r) else 2 * r
                i = ci - r
                while i <= ci + r:
                    c = j * ncx + i
                    if 0 <= i < ncx and start[c] < start[c + 1]:
                        gx = max(max(x0 + i * cell - tol - x, x - (x0 + (i + 1) * cell + tol)), 0.0)
                        # skip a cell farther than the best so far (nothing in it can tie)
                        if (gx * gx + gy * gy) * (1.0 - _MARGIN) <= best:
                            best, best_n, bx, by = _scan_cell(
                                x, y, segs, start, members, c, best, best_n, bx, by
                            )
                    i += step
            # every unvisited cell is more than r cells away from the point's cell: its
            # segments are at least r·cell away
            reach = max(r * cell - tol, 0.0)
            if best_n >= 0 and reach * reach * (1.0 - _MARGIN) > best:
                break
        out_x[p], out_y[p], out_i[p] = bx, by, best_n
        out_d[p] = np.sqrt(best)


def _outputs(px):
    return (
        np.empty_like(px),
        np.empty_like(px),
        np.empty_like(px),
        np.empty(px.shape, dtype=np.int64),
    )


def nearest_segment_brute(px, py, segs):
    """Reference: scan all segments for every point. Same return as :func:`nearest_segment`."""
    px = np.ascontiguousarray(px, dtype=np.float64)
    py = np.ascontiguousarray(py, dtype=np.float64)
    out_d, out_x, out_y, out_i = _outputs(px)
    _brute_kernel(px, py, np.ascontiguousarray(segs, dtype=np.float64), out_d, out_x, out_y, out_i)
    return out_d, out_x, out_y, out_i


def nearest_segment(px, py, segs):
    """Exact nearest point on segments ``segs`` (n, 4: x1, y1, x2, y2) to each point (px, py).

    Returns (distance, nearest x, nearest y, segment index), bit-identical to
    :func:`nearest_segment_brute` (ties: the lowest index).
    """
    segs = np.ascontiguousarray(segs, dtype=np.float64)
    if segs.shape[0] < _BRUTE_FORCE_BELOW:
        return nearest_segment_brute(px, py, segs)
    px = np.ascontiguousarray(px, dtype=np.float64)
    py = np.ascontiguousarray(py, dtype=np.float64)
    xmin = float(min(segs[:, 0].min(), segs[:, 2].min()))
    xmax = float(max(segs[:, 0].max(), segs[:, 2].max()))
    ymin = float(min(segs[:, 1].min(), segs[:, 3].min()))
    ymax = float(max(segs[:, 1].max(), segs[:, 3].max()))
    width, height = xmax - xmin, ymax - ymin
    mean_length = float(np.mean(np.hypot(segs[:, 2] - segs[:, 0], segs[:, 3] - segs[:, 1])))
    # about one segment per cell on average over the bounding box (measured fastest on the
    # reshuffler, whose wall field asks for points up to ~260 nm from the walls), at least two
    # segment lengths
    cell = max(
        math.sqrt(width * height / segs.shape[0]), 2 * mean_length, 1e-6 * max(width, height, 1.0)
    )
    ncx = int(width // cell) + 1
    ncy = int(height // cell) + 1
    start, members = _bucket(segs, xmin, ymin, cell, ncx, ncy)
    out_d, out_x, out_y, out_i = _outputs(px)
    _grid_kernel(
        px, py, segs, xmin, ymin, cell, ncx, ncy, start, members, out_d, out_x, out_y, out_i
    )
    return out_d, out_x, out_y, out_i
