"""The overlay movie: the input frames, scaled up, with each located skyrmion circled.

The circles are drawn where the skyrmions are in the picture: a subtracted drift is added back.

Every located skyrmion gets a circle of trackpy's ``diameter`` in its track's colour and a tail
through its last ``TAIL`` positions; frames are scaled up by a whole factor (nearest
neighbour) to at least ``MIN_WIDTH`` pixels and their grey levels stretched between the
0.5th and 99.5th percentiles of the first frame. Encoded as H.264 MP4 with ffmpeg, with the
settings of ``skygas animate`` (:func:`skygas.outputs.movie.write_mp4`), but with ffmpeg's
messages kept off the terminal and its failure (a full disk, found only when it writes the
trailer) raised as an :class:`OSError`; long movies are shown every N-th frame, at most
``MAX_FRAMES`` of them.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np

#: frames of tail behind each skyrmion
TAIL = 12
#: the smallest width of the overlay [px]
MIN_WIDTH = 320
#: the most frames of the overlay
MAX_FRAMES = 1200
#: frames per second
FPS = 25
#: the tracks' colours (RGB), cycled by particle number
COLOURS = (
    (230, 97, 1),
    (94, 60, 153),
    (27, 158, 119),
    (217, 95, 2),
    (231, 41, 138),
    (102, 166, 30),
    (230, 171, 2),
    (31, 120, 180),
)


def _scale(shape: tuple[int, int]) -> int:
    return max(1, math.ceil(MIN_WIDTH / shape[1]))


def _grey(image: np.ndarray, lo: float, hi: float, scale: int) -> np.ndarray:
    grey = np.clip((image - lo) / (hi - lo) * 255 if hi > lo else image * 0, 0, 255)
    grey = np.repeat(np.repeat(grey.astype(np.uint8), scale, axis=0), scale, axis=1)
    return np.stack([grey] * 3, axis=-1)


def overlay_frames(movie, tracks, diameter: float, indices):
    """The RGB overlay frames (height, width, 3) uint8 at frame ``indices`` of ``movie``."""
    from PIL import Image, ImageDraw

    table = tracks.table
    if tracks.drift is not None:  # draw where the skyrmions are in the picture, drift included
        shift = tracks.drift[table["frame"].to_numpy()]
        table = table.assign(x=table["x"] + shift[:, 0], y=table["y"] + shift[:, 1])
    first = movie.frame(0)
    lo, hi = np.percentile(first, [0.5, 99.5])
    scale = _scale(movie.shape)
    radius = 0.5 * diameter * scale
    by_frame = {f: g for f, g in table.groupby("frame")}
    # each track's frames (sorted) and positions as arrays: a tail is a slice found by bisection
    by_particle = {
        p: (g["frame"].to_numpy(), g[["x", "y"]].to_numpy())
        for p, g in table.sort_values("frame").groupby("particle")
    }
    for f in indices:
        image = Image.fromarray(_grey(movie.frame(int(f)), lo, hi, scale))
        draw = ImageDraw.Draw(image)
        here = by_frame.get(int(f))
        if here is not None:
            for particle, x, y in here[["particle", "x", "y"]].itertuples(index=False):
                colour = COLOURS[int(particle) % len(COLOURS)]
                frames, xy = by_particle[particle]
                start, end = np.searchsorted(frames, [f - TAIL, f], side="right")
                points = [((px + 0.5) * scale, (py + 0.5) * scale) for px, py in xy[start:end]]
                if len(points) > 1:
                    draw.line(points, fill=colour, width=max(1, scale // 3))
                cx, cy = (x + 0.5) * scale, (y + 0.5) * scale
                draw.ellipse(
                    (cx - radius, cy - radius, cx + radius, cy + radius),
                    outline=colour,
                    width=max(1, scale // 3),
                )
        draw.text((4, 4), f"frame {int(f)}", fill=(255, 255, 0))
        yield np.asarray(image)


def write_overlay(path: str | Path, movie, tracks, diameter: float) -> dict:
    """Write the overlay movie of ``tracks`` on ``movie`` to ``path`` (.mp4), atomically.

    Returns
    -------
    dict
        ``path``, ``frames``, ``stride``, ``fps``, ``width_px``, ``height_px``, ``bytes``.
    """
    from skygas.runs.run_driver import write_atomic
    from skygas.runs.video import encode_mp4

    path = Path(path)
    stride = max(1, math.ceil(movie.n_frames / MAX_FRAMES))
    indices = range(0, movie.n_frames, stride)
    images = overlay_frames(movie, tracks, diameter, indices)
    first = next(images)
    # H.264 wants sizes in whole macro blocks: pad to multiples of 16
    h, w = first.shape[:2]
    H, W = 16 * math.ceil(h / 16), 16 * math.ceil(w / 16)

    def padded(image):
        out = np.zeros((H, W, 3), np.uint8)
        out[:h, :w] = image
        return out

    def frames():
        yield padded(first)
        yield from (padded(i) for i in images)

    # "veryfast" at crf 32 keeps the overlay small
    write_atomic(path, lambda tmp: encode_mp4(tmp, frames(), (W, H), FPS))
    return {
        "path": path.name,
        "frames": len(indices),
        "stride": stride,
        "fps": FPS,
        "width_px": W,
        "height_px": H,
        "bytes": path.stat().st_size,
    }
