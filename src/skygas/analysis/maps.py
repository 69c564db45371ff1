"""Maps and counts over the device: number density, velocity field and occupancy.

- density n(x, y) [1/m²] = (entries in the cell) / (frames × cell area): the time-averaged
  number of skyrmion centres per unit area;
- velocity field [m/s]: the mean of Δr/τ over the displacements between consecutive frames
  whose midpoint falls in the cell (NaN where none does);
- occupancy: skyrmions present in each frame, in total and per labelled part of the device.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from skygas.analysis.frames import Frames


@dataclass(frozen=True)
class FieldMap:
    """A map over square cells of the device.

    Cell ``x_edges``, ``y_edges`` [m] and ``values`` (ny, nx); velocity maps fill ``u``, ``v`` too;
    ``samples`` per cell.
    """

    x_edges: np.ndarray
    y_edges: np.ndarray
    values: np.ndarray
    samples: np.ndarray
    u: np.ndarray | None = None
    v: np.ndarray | None = None


def _edges(frames: Frames, bins: int, extent) -> tuple[np.ndarray, np.ndarray]:
    if extent is None:
        extent = (frames.x.min(), frames.x.max(), frames.y.min(), frames.y.max())
    x0, x1, y0, y1 = extent
    side = max(x1 - x0, y1 - y0) / bins  # square cells
    nx = max(1, int(np.ceil((x1 - x0) / side)))
    ny = max(1, int(np.ceil((y1 - y0) / side)))
    return x0 + side * np.arange(nx + 1), y0 + side * np.arange(ny + 1)


def density_map(frames: Frames, bins: int = 40, extent=None) -> FieldMap:
    """Time-averaged number density [1/m²] on square cells.

    Parameters
    ----------
    frames : Frames
        The recorded positions.
    bins : int
        Cells along the longer side of ``extent``.
    extent : tuple of float, optional
        (x0, x1, y0, y1) [m] (default: the positions' bounding box).

    Returns
    -------
    FieldMap
        ``values``: the density [1/m²]; ``samples``: entries per cell.
    """
    xe, ye = _edges(frames, bins, extent)
    counts = np.histogram2d(frames.y, frames.x, [ye, xe])[0]
    area = (xe[1] - xe[0]) * (ye[1] - ye[0])
    return FieldMap(xe, ye, counts / (max(frames.n_frames, 1) * area), counts)


def velocity_map(frames: Frames, bins: int = 20, extent=None) -> FieldMap:
    """Mean velocity [m/s] on square cells from displacements between consecutive frames.

    A displacement counts in the cell of its midpoint; cells without one are NaN.

    Parameters
    ----------
    frames : Frames
        The recorded positions, evenly spaced in time.
    bins : int
        Cells along the longer side of ``extent``.
    extent : tuple of float, optional
        (x0, x1, y0, y1) [m] (default: the positions' bounding box).

    Returns
    -------
    FieldMap
        ``values`` holds the speed of the mean velocity [m/s], ``u``, ``v`` its components,
        ``samples`` the displacements per cell.
    """
    dt = frames.frame_interval()
    xe, ye = _edges(frames, bins, extent)
    a, b = frames.pairs_at_lag(1)
    mx, my = 0.5 * (frames.x[a] + frames.x[b]), 0.5 * (frames.y[a] + frames.y[b])
    n = np.histogram2d(my, mx, [ye, xe])[0]
    with np.errstate(invalid="ignore", divide="ignore"):
        u = np.histogram2d(my, mx, [ye, xe], weights=(frames.x[b] - frames.x[a]) / dt)[0] / n
        v = np.histogram2d(my, mx, [ye, xe], weights=(frames.y[b] - frames.y[a]) / dt)[0] / n
    return FieldMap(xe, ye, np.hypot(u, v), n, u, v)


def occupancy(frames: Frames, label_of=None, names=None) -> dict:
    """Skyrmions present per frame, in total and per labelled part of the device.

    Parameters
    ----------
    frames : Frames
        The recorded positions.
    label_of : callable, optional
        A function of x, y [m] giving an integer label per entry.
    names : sequence of str, optional
        The name of each label (label k is ``names[k]``); needed with ``label_of``.

    Returns
    -------
    dict
        ``time_s``, ``total`` per frame, ``mean_total`` and ``max_total``; with ``label_of``, the
        count per frame and ``mean_<name>`` of each name.
    """
    out = {
        "time_s": frames.time.tolist(),
        "total": frames.count.tolist(),
        "mean_total": float(frames.count.mean()) if frames.n_frames else float("nan"),
        "max_total": int(frames.count.max(initial=0)),
    }
    if label_of is not None:
        labels = np.asarray(label_of(frames.x, frames.y))
        frame = frames.frame_of_entry
        for k, name in enumerate(names):
            per = np.bincount(frame[labels == k], minlength=frames.n_frames)
            out[name] = per.tolist()
            out[f"mean_{name}"] = float(per.mean()) if frames.n_frames else float("nan")
    return out
