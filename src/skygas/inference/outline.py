"""The device outline of a movie: a CSV of polygon vertices in metres, or a binary mask image.

A CSV holds columns ``x`` and ``y`` [m] (or two unnamed columns), one vertex per row, in order
along the boundary. A mask image (PNG, TIFF, ...) is on the tracks' pixel grid: pixel (row i,
column j) is centred on x = j, y = i pixels and covers x ∈ [j − ½, j + ½), y ∈ [i − ½, i + ½)
(trackpy's convention: x is the column, y the row, from the first pixel of the image's first
row); the film is where the image is non-zero, and the outline is the union of those pixels, as
a polygon in metres.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from skygas.core.errors import InputError, require
from skygas.physics.geometry import Outline


def read_outline(source, pixel_size: float) -> Outline:
    """The outline from ``source`` (a path, or an :class:`Outline` returned as it is).

    Raises
    ------
    InputError
        If the file is missing, unreadable, or describes no area.
    """
    if isinstance(source, Outline):
        return source
    path = Path(str(source))
    require(
        path.is_file(), "--outline", str(source), "an existing .csv of x,y vertices or a mask image"
    )
    if path.suffix.lower() in (".csv", ".txt"):
        return _polygon_csv(path)
    return _mask_outline(path, pixel_size)


def _polygon_csv(path: Path) -> Outline:
    import pandas as pd

    from skygas.physics.geometry import polygon

    try:
        table = pd.read_csv(path, comment="#")
        if not {"x", "y"} <= set(table.columns):
            table = pd.read_csv(path, comment="#", header=None)
            table = table.rename(columns={0: "x", 1: "y"})
        xy = table[["x", "y"]].to_numpy(float)
    except (ValueError, KeyError, OSError) as err:
        raise InputError(
            "--outline", str(path), f"a CSV of x,y vertices in metres ({type(err).__name__})"
        ) from None
    require(
        bool(len(xy) >= 3 and np.all(np.isfinite(xy))),
        "--outline",
        str(path),
        "at least three finite x,y vertices in metres",
    )
    return polygon(xy)


def _mask_outline(path: Path, pixel_size: float) -> Outline:
    import shapely
    from shapely.geometry import box

    from skygas.core.units import M_TO_NM

    try:
        import matplotlib.image

        image = np.asarray(matplotlib.image.imread(path), dtype=float)
    except (OSError, ValueError, SyntaxError) as err:
        raise InputError(
            "--outline", str(path), f"a readable mask image or CSV ({type(err).__name__})"
        ) from None
    if image.ndim == 3:
        image = image[..., :3].mean(axis=2)
    mask = image > 0
    require(bool(mask.any()), "--outline", str(path), "a mask with non-zero (film) pixels")
    # one box per run of film pixels in a row, merged: fast even for large masks
    boxes = []
    for i, row in enumerate(mask):
        edges = np.flatnonzero(np.diff(np.concatenate([[0], row.astype(np.int8), [0]])))
        for j0, j1 in zip(edges[::2], edges[1::2], strict=True):
            boxes.append(box(j0 - 0.5, i - 0.5, j1 - 0.5, i + 0.5))
    region = shapely.union_all(boxes).simplify(0)
    region = shapely.affinity.scale(
        region, pixel_size * M_TO_NM, pixel_size * M_TO_NM, origin=(0, 0)
    )
    if isinstance(region, shapely.GeometryCollection) and not isinstance(
        region, (shapely.Polygon, shapely.MultiPolygon)
    ):
        raise InputError("--outline", str(path), "a mask whose film pixels form an area")
    return Outline(region)
