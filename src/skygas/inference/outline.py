"""The device outline of a movie: a CSV of polygon vertices in metres, or a binary mask image.

A CSV holds columns ``x`` and ``y`` [m] (or two unnamed columns), one vertex per row, in order
along the boundary. A mask image (PNG, TIFF, ...) is on the tracks' pixel grid: pixel (row i,
column j) is centred on x = j, y = i pixels and covers x ∈ [j − ½, j + ½), y ∈ [i − ½, i + ½)
(trackpy's convention: x is the column, y the row, from the first pixel of the image's first
row); the film is where the image is non-zero, and the outline is the union of those pixels, as
a polygon in metres. A mask has one grey or 1-bit channel (an RGB image whose channels are all
equal is grey too; a constant alpha channel is left out) and both kinds of pixel: film and
outside.

Both are judged before any work: a polygon's size must be a length the devices accept (1 pm …
1 m: a polygon in nanometres is refused with "did you mean ...e-9"), a mask must say where the
device ends.
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

    from skygas.inference.tracks import metres
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
    finite = np.isfinite(xy).all(axis=1)
    require(
        bool(finite.all()),
        "--outline",
        str(path),
        f"finite x,y vertices in metres (row {int(np.argmin(finite)) + 1} is not)",
        "fix or remove that row",
    )
    require(len(xy) >= 3, "--outline", str(path), "at least three x,y vertices in metres")
    # a polygon drawn in nanometres or in pixels is far over a metre across
    metres(
        "--outline",
        float(np.max(xy.max(axis=0) - xy.min(axis=0))),
        f"the size of the polygon of {path} (its x,y vertices are in metres)",
    )
    try:
        return polygon(xy)
    except InputError as err:
        raise InputError(
            "--outline", str(path), f"a polygon that does not cross itself ({err.allowed})"
        ) from None


def _mask_outline(path: Path, pixel_size: float) -> Outline:
    import shapely
    from shapely.geometry import box

    from skygas.core.units import M_TO_NM

    mask = _mask(path)
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


#: What a mask image must be, as the refusals say it.
MASK_RULE = "one grey or 1-bit channel, the device's pixels non-zero and the rest zero"


def _mask(path: Path) -> np.ndarray:
    """The film pixels (bool, rows × columns) of the mask image at ``path``, checked."""
    try:
        import matplotlib.image

        image = np.asarray(matplotlib.image.imread(path), dtype=float)
    except (OSError, ValueError, SyntaxError) as err:
        raise InputError(
            "--outline", str(path), f"a readable mask image or CSV ({type(err).__name__})"
        ) from None
    if image.ndim == 3:
        channels = image.shape[2]
        if channels in (2, 4) and np.ptp(image[..., -1]) == 0:
            image = image[..., :-1]  # an alpha channel that hides nothing
        # a grey image stored as RGB has equal channels; anything else is colour
        require(
            bool(np.all(image == image[..., :1])),
            "--outline",
            str(path),
            f"a mask of {MASK_RULE} (this image has {channels} channels that differ: colour)",
            "save the mask as a grey or 1-bit image (e.g. PIL: Image.open(f).convert('L'))",
        )
        image = image[..., 0]
    require(
        image.ndim == 2,
        "--outline",
        str(path),
        f"a mask image of {MASK_RULE} (this one has shape {image.shape})",
    )
    mask = image > 0
    require(
        bool(mask.any() and not mask.all()),
        "--outline",
        str(path),
        f"a mask of {MASK_RULE}: some of each (this one is all "
        f"{'non-zero' if mask.all() else 'zero'}, which outlines no device)",
        "draw the device's pixels non-zero and the rest zero, or leave --outline out: the "
        "field of view is then the tracks' extent",
    )
    return mask
