"""The overlay movie: the input frames, scaled up, with each located skyrmion circled.

The circles are drawn where the skyrmions are in the picture: a subtracted drift is added back.

Every located skyrmion gets a circle of trackpy's ``diameter`` in its track's colour and a tail
through its last ``TAIL`` positions; frames are scaled up by a whole factor (nearest
neighbour) to at least ``MIN_WIDTH`` pixels and their grey levels stretched between the
0.5th and 99.5th percentiles of the first frame. Row 0 of a frame is at the top, as image
viewers show it. Below the picture, outside it, a strip holds the frame's number (and time, when
the frame interval is known) and a scale bar: a length in nm or µm from the pixel size, or in
pixels when the pixel size is not known. Encoded as H.264 MP4 with ffmpeg, with the settings of
``skygas animate`` (:func:`skygas.outputs.movie.write_mp4`), but with ffmpeg's messages kept off
the terminal and its failure (a full disk, found only when it writes the trailer) raised as an
:class:`OSError`; long movies are shown every N-th frame, at most ``MAX_FRAMES`` of them.
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
#: the white margin around the picture [px]
MARGIN_PX = 8
#: the strip below the picture that holds the stamp and the scale bar [px]
STRIP_PX = 30
#: the stamp's font size [px]
STAMP_PX = 13
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


class OverlayCanvas:
    """The overlay's fixed layout, drawn once with matplotlib; each frame is painted into it.

    ``figure``: the matplotlib figure (white, sized in whole multiples of 16 px for H.264) with
    ``axes`` where the picture goes (the movie's pixels, scaled ``scale`` times, row 0 at the
    top, no ticks) and, below them in the strip, the ``scale_bar`` (right); the stamp is
    painted per frame at ``stamp_xy`` (left of the strip). ``picture_xy``: the picture's top
    left corner in the frame [px]; ``bar_length``: the bar's length in metres (or in movie
    pixels, when ``pixel_size`` is None); ``image``: the static frame (height, width, 3) uint8.

    Parameters
    ----------
    shape : (rows, columns)
        The movie's frame shape [px].
    scale : int
        Display pixels per movie pixel.
    pixel_size : float, optional
        Metres per movie pixel.
    """

    def __init__(self, shape: tuple[int, int], scale: int, pixel_size: float | None = None):
        from matplotlib.backends.backend_agg import FigureCanvasAgg
        from matplotlib.figure import Figure
        from matplotlib.font_manager import FontProperties
        from mpl_toolkits.axes_grid1.anchored_artists import AnchoredSizeBar

        from skygas.outputs.movie import length_label, nice_length

        rows, columns = shape
        w, h = columns * scale, rows * scale
        width = 16 * math.ceil((w + 2 * MARGIN_PX) / 16)
        height = 16 * math.ceil((h + MARGIN_PX + STRIP_PX) / 16)
        x0 = (width - w) // 2
        self.picture_xy = (x0, MARGIN_PX)
        dpi = 100
        fig = Figure(figsize=(width / dpi, height / dpi), dpi=dpi, facecolor="white")
        # the picture's place, in whole display pixels: painted pixels and data meet exactly
        ax = fig.add_axes((x0 / width, (height - MARGIN_PX - h) / height, w / width, h / height))
        ax.set_xlim(-0.5, columns - 0.5)
        ax.set_ylim(rows - 0.5, -0.5)  # row 0 at the top
        ax.set_axis_off()
        if pixel_size is not None:
            self.bar_length = nice_length(0.25 * columns * pixel_size)
            bar_px = self.bar_length / pixel_size
            label = length_label(self.bar_length)
        else:  # no scale known: a bar of pixels says as much as can be said
            self.bar_length = nice_length(0.25 * columns)
            bar_px = self.bar_length
            label = f"{self.bar_length:g} px"
        # a figure's artist (one of the axes would be clipped to them), just below the picture
        self.scale_bar = AnchoredSizeBar(
            ax.transData,
            bar_px,
            label,
            "upper right",
            bbox_to_anchor=(1.0, 0.0),
            bbox_transform=ax.transAxes,
            borderpad=0.2,
            pad=0.1,
            frameon=False,
            size_vertical=0,
            fontproperties=FontProperties(size=9),
        )
        fig.add_artist(self.scale_bar)
        agg = FigureCanvasAgg(fig)
        agg.draw()
        self.figure = fig
        self.axes = ax
        self.scale = scale
        self.image = np.asarray(agg.buffer_rgba())[..., :3].copy()
        self.stamp_xy = (x0, MARGIN_PX + h + (STRIP_PX - STAMP_PX) // 2)

    def stamp(self, frame: int, frame_interval: float | None) -> str:
        """The stamp of ``frame``: its number, and its time when ``frame_interval`` [s] is known."""
        from skygas.core.quantities import format_value

        text = f"frame {frame}"
        if frame_interval:
            text += f"   t = {format_value(frame * frame_interval, unit='s', digits=4)}"
        return text


def overlay_frames(
    movie,
    tracks,
    diameter: float,
    indices,
    *,
    pixel_size: float | None = None,
    frame_interval: float | None = None,
):
    """The RGB overlay frames (height, width, 3) uint8 at frame ``indices`` of ``movie``.

    ``pixel_size`` [m] sets the scale bar (in pixels without one); ``frame_interval`` [s]
    adds the time to the stamp.
    """
    from PIL import Image, ImageDraw

    from skygas.outputs.movie import font

    table = tracks.table
    if tracks.drift is not None:  # draw where the skyrmions are in the picture, drift included
        shift = tracks.drift[table["frame"].to_numpy()]
        table = table.assign(x=table["x"] + shift[:, 0], y=table["y"] + shift[:, 1])
    first = movie.frame(0)
    lo, hi = np.percentile(first, [0.5, 99.5])
    scale = _scale(movie.shape)
    canvas = OverlayCanvas(movie.shape, scale, pixel_size)
    base = Image.fromarray(canvas.image)
    stamp_font = font(STAMP_PX)
    radius = 0.5 * diameter * scale
    by_frame = {f: g for f, g in table.groupby("frame")}
    # each track's frames (sorted) and positions as arrays: a tail is a slice found by bisection
    by_particle = {
        p: (g["frame"].to_numpy(), g[["x", "y"]].to_numpy())
        for p, g in table.sort_values("frame").groupby("particle")
    }
    for f in indices:
        # drawn on the picture alone: a circle at its edge is cut there, never spills out
        picture = Image.fromarray(_grey(movie.frame(int(f)), lo, hi, scale))
        draw = ImageDraw.Draw(picture)
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
        image = base.copy()
        image.paste(picture, canvas.picture_xy)
        ImageDraw.Draw(image).text(
            canvas.stamp_xy, canvas.stamp(int(f), frame_interval), fill=(0, 0, 0), font=stamp_font
        )
        yield np.asarray(image)


def write_overlay(
    path: str | Path,
    movie,
    tracks,
    diameter: float,
    *,
    pixel_size: float | None = None,
    frame_interval: float | None = None,
) -> dict:
    """Write the overlay movie of ``tracks`` on ``movie`` to ``path`` (.mp4), atomically.

    ``diameter``: the circles' [px]; ``pixel_size`` [m] and ``frame_interval`` [s], when known,
    give the scale bar its length in metres and the stamp its time (:func:`overlay_frames`).

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
    images = overlay_frames(
        movie, tracks, diameter, indices, pixel_size=pixel_size, frame_interval=frame_interval
    )
    first = next(images)
    H, W = first.shape[:2]  # whole macro blocks of 16 px (OverlayCanvas), as H.264 wants

    def frames():
        yield first
        yield from images

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
