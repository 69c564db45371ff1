"""Movies of the gas: MP4 (H.264 through the ffmpeg that the imageio-ffmpeg wheel ships) or GIF.

GIF through Pillow.

Each frame shows the device outline over its energy landscape (U/k_BT) when the run has one,
else over its current density (log colour scale; plain grey without a current), the skyrmions
as disks of their real diameter coloured by their group (the input bit they carry in the
reshuffler) and, outside the device, a time stamp, a scale bar and the groups' legend.

Speed: the static picture (outline, current, colour bar, legend, scale bar) is drawn once with
matplotlib; every frame then only paints disks and the time stamp onto a copy of it with
Pillow (~1 ms per frame), and ffmpeg encodes in a separate process. A 1 000-frame movie takes a
few seconds on one core.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from skygas.core.errors import InputError

#: colours of the skyrmion groups (RGB), in group order
GROUP_COLOURS = ((230, 97, 1), (94, 60, 153), (150, 150, 150))
FORMATS = (".mp4", ".gif")
#: frames per second of the movie
FPS = 25
#: default most frames: 48 s of MP4; GIFs are larger per frame and get fewer
MAX_FRAMES = {".mp4": 1200, ".gif": 300}
#: the tallest frame [px]
MAX_HEIGHT = 1024
#: the time between frames a run records when a movie is asked for (``--animate``): a skyrmion
#: crossing the reshuffler's chamber (~1 µm in ~200 ns at the default current) moves about
#: 20 nm, half a diameter, per frame; 1 200 frames show the first 4.8 µs of a run
MOVIE_FRAME_INTERVAL = 4e-9


@dataclass(frozen=True)
class MovieInfo:
    """What :func:`render_movie` wrote.

    ``path``, ``frames``, ``stride``, the covered time ``start``–``end`` [s], ``fps``, ``bytes`` and
    the frame ``size`` (width, height) [px].
    """

    path: Path
    frames: int
    stride: int
    start: float
    end: float
    fps: int
    bytes: int
    size: tuple[int, int]

    def as_dict(self) -> dict:
        """The record as a JSON-able dict, units in the keys."""
        return {
            "path": str(self.path),
            "frames": self.frames,
            "stride": self.stride,
            "start_s": self.start,
            "end_s": self.end,
            "fps": self.fps,
            "bytes": self.bytes,
            "width_px": self.size[0],
            "height_px": self.size[1],
        }


def check_movie_path(path: str | Path) -> Path:
    """Refuse an output name without a known movie suffix or in a missing directory."""
    path = Path(path)
    if path.suffix.lower() not in FORMATS:
        raise InputError("--out", str(path), f"a file name ending in {' or '.join(FORMATS)}")
    if not path.parent.is_dir():
        raise InputError("--out", str(path), "a file in an existing directory")
    return path


def choose_frames(
    times: np.ndarray,
    *,
    stride: int | None = None,
    start: float | None = None,
    end: float | None = None,
    max_frames: int = 1200,
) -> tuple[np.ndarray, int]:
    """Indices of the frames in [start, end] [s], every ``stride``-th, and the stride.

    The default stride is the smallest that keeps at most ``max_frames``.
    """
    keep = np.ones(len(times), bool)
    if start is not None:
        keep &= times >= start
    if end is not None:
        keep &= times <= end
    index = np.flatnonzero(keep)
    if len(index) == 0:
        raise InputError(
            "--window",
            f"{start}:{end}",
            f"a window that holds recorded frames "
            f"(the record spans {times[0]:.4g}–{times[-1]:.4g} s)"
            if len(times)
            else "a run that recorded frames",
        )
    if stride is None:
        stride = max(1, math.ceil(len(index) / max_frames))
    return index[::stride], stride


#: the margins of a movie frame [px]: below the chamber its tick labels and axis label, above
#: it the time stamp and the scale bar, left of it the y axis, right of it the colour bar
#: (tick labels such as 6×10¹⁰ and its label) or a little air
BOTTOM_PX = 45
TOP_PX = 45
LEFT_PX = 72
RIGHT_PX = {True: 130, False: 24}
#: the narrowest chamber drawn [px]: a narrower ``width_px`` is widened to hold it and the margins
MIN_AXES_PX = 96
#: the gap between the legend's band and the stamp row [px]
LEGEND_GAP_PX = 6


class _Canvas:
    """The static picture and the map from positions [m] to its pixels.

    The chamber's axes fill the middle; above them, outside the device, the time stamp (left,
    painted per frame) and the scale bar (right); above those, in a band of its own at the top
    right, the legend of the skyrmions' groups; right of them the colour bar. Nothing but the
    skyrmions is drawn over the device. ``figure`` is the matplotlib figure the static picture
    is drawn on; ``width_px`` the frame's width [px], at least the margins and
    :data:`MIN_AXES_PX`.
    """

    def __init__(self, record, width_px: int):
        from matplotlib.backends.backend_agg import FigureCanvasAgg
        from matplotlib.figure import Figure
        from matplotlib.patches import Patch
        from mpl_toolkits.axes_grid1.anchored_artists import AnchoredSizeBar

        from skygas.figures.plotting import draw_outline

        x0, y0, x1, y1 = np.array(record.outline._bounds_nm) * 1e-3  # µm
        aspect = (y1 - y0) / (x1 - x0)
        background = record.background()
        dpi = 100
        fig = Figure(figsize=(width_px / dpi, 1.0), dpi=dpi)
        agg = FigureCanvasAgg(fig)
        f = record.frames
        shown: np.ndarray | list = np.unique(record.group_of(f.ids, f.x, f.y)) if len(f.ids) else []
        self.legend = None
        band = 0.0
        if len(record.group_names) > 1 and len(shown):
            handles = [
                Patch(color=tuple(np.array(GROUP_COLOURS[g]) / 255), label=record.group_names[g])
                for g in shown
            ]
            self.legend = fig.legend(
                handles=handles,
                loc="upper right",
                bbox_to_anchor=(1.0, 1.0),
                fontsize=7,
                frameon=False,
            )
            # the legend's height in pixels (its font's, whatever the figure's size): a band
            # of that height is kept free above the stamp row, so it never covers the device
            band = self.legend.get_window_extent(agg.get_renderer()).height + LEGEND_GAP_PX
        margins = BOTTOM_PX + TOP_PX + band
        sides = LEFT_PX + RIGHT_PX[background is not None]
        # sizes in whole multiples of 16 px: H.264 encoders want even sizes, and ffmpeg
        # would rescale sizes that are not multiples of its macro block
        # a tall device (the reshuffler's two chambers) is narrowed to MAX_HEIGHT: pixels are
        # what painting and encoding cost
        inner = min(width_px - sides, (MAX_HEIGHT - margins) / aspect)
        width = 16 * math.floor((max(inner, MIN_AXES_PX) + sides) / 16)
        height = 16 * max(8, round(((width - sides) * aspect + margins) / 16))
        fig.set_size_inches(width / dpi, height / dpi)
        ax = fig.add_axes(
            (
                LEFT_PX / width,
                BOTTOM_PX / height,
                (width - sides) / width,
                (height - margins) / height,
            )
        )
        image = None
        if background is not None:
            from matplotlib.colors import LogNorm

            values, extent, label, scale = background
            finite = values[np.isfinite(values) & (values > 0)]
            norm = (
                LogNorm(vmin=max(finite.min(), finite.max() * 1e-3), vmax=finite.max())
                if finite.size and scale == "log"
                else None
            )
            image = ax.imshow(
                values,
                origin="lower",
                extent=tuple(np.array(extent) * 1e6),
                cmap="Greys_r",
                norm=norm,
                alpha=0.85,
            )
        else:
            regions = getattr(record.outline.region, "geoms", [record.outline.region])
            for part in regions:
                xy = np.asarray(part.exterior.coords) * 1e-3
                ax.fill(xy[:, 0], xy[:, 1], color="0.92", zorder=0)
        draw_outline(ax, record.outline, labels=False)
        ax.set_xlim(x0 - 0.02 * (x1 - x0), x1 + 0.02 * (x1 - x0))
        ax.set_ylim(y0 - 0.02 * (y1 - y0), y1 + 0.02 * (y1 - y0))
        if image is not None:  # beside the chamber as drawn (its aspect kept), half as tall
            ax.apply_aspect()
            box = ax.get_position()
            cax = fig.add_axes(
                (box.x1 + 14 / width, box.y0 + 0.25 * box.height, 14 / width, 0.5 * box.height)
            )
            fig.colorbar(image, cax=cax, label=label)
        bar_um = nice_length(0.25 * (x1 - x0))
        # above the axes' top right corner, outside the device (a figure's artist: one of the
        # axes would be clipped to them)
        self.scale_bar = AnchoredSizeBar(
            ax.transData,
            bar_um,
            length_label(bar_um * 1e-6),
            "lower right",
            bbox_to_anchor=(1.0, 1.0),
            bbox_transform=ax.transAxes,
            borderpad=0.1,
            pad=0.1,
            frameon=False,
            size_vertical=0,
        )
        fig.add_artist(self.scale_bar)
        agg.draw()
        self.figure = fig
        self.axes = ax
        self.image = np.asarray(agg.buffer_rgba())[..., :3].copy()
        self.height, self.width = self.image.shape[:2]
        # data (µm) → display pixels (origin bottom left) → image rows (origin top left)
        (px0, py0), (px1, py1) = ax.transData.transform([(0.0, 0.0), (1.0, 1.0)])
        self.px_per_um = px1 - px0
        self.origin = (px0, self.height - py0)
        bbox = ax.get_window_extent()
        self.stamp_xy = (bbox.x0, self.height - bbox.y1 - 24)  # above the axes, clear of walls
        self.radius_px = max(1.0, 0.5 * record.skyrmion_diameter * 1e6 * self.px_per_um)

    def pixels(self, xy_m: np.ndarray) -> np.ndarray:
        return np.column_stack(
            [
                self.origin[0] + xy_m[:, 0] * 1e6 * self.px_per_um,
                self.origin[1] - xy_m[:, 1] * 1e6 * self.px_per_um,
            ]
        )


def nice_length(length: float) -> float:
    """The longest of 1, 2 or 5 × 10ⁿ (in the unit of ``length``) not above ``length`` > 0."""
    exponent = math.floor(math.log10(length))
    for m in (5, 2, 1):
        if m * 10**exponent <= length:
            return m * 10**exponent
    return 10**exponent


def length_label(metres: float) -> str:
    """A scale bar's label: ``metres`` with an SI prefix, "200 nm", "1 µm" (no e-notation)."""
    from skygas.core.quantities import format_value

    return format_value(metres, unit="m", digits=3) or f"{metres} m"


def _time_label(t: float) -> str:
    return f"t = {t * 1e6:.3f} µs" if t >= 1e-6 else f"t = {t * 1e9:.1f} ns"


def font(size: int):
    """The DejaVu Sans font (matplotlib's own) at ``size`` pixels, for Pillow's stamps."""
    from matplotlib import font_manager
    from PIL import ImageFont

    return ImageFont.truetype(font_manager.findfont("DejaVu Sans"), size)


def frame_images(record, indices, width_px: int = 720):
    """The RGB frames (height, width, 3) uint8 of ``record`` at frame ``indices``."""
    from PIL import Image, ImageDraw

    canvas = _Canvas(record, width_px)
    base = Image.fromarray(canvas.image)
    stamp_font = font(15)
    frames = record.frames
    r = canvas.radius_px
    fills = [tuple(c) for c in GROUP_COLOURS]
    for f in indices:
        ids, xy = frames.frame(int(f))
        image = base.copy()
        draw = ImageDraw.Draw(image)
        groups = record.group_of(ids, xy[:, 0], xy[:, 1])
        for (px, py), g in zip(canvas.pixels(xy), groups, strict=True):
            draw.ellipse(
                (px - r, py - r, px + r, py + r), fill=fills[int(g) % len(fills)], outline=(0, 0, 0)
            )
        draw.text(
            canvas.stamp_xy,
            f"{_time_label(frames.time[f])}   N = {len(ids)}",
            fill=(0, 0, 0),
            font=stamp_font,
        )
        yield np.asarray(image)


def render_movie(
    record,
    path: str | Path,
    *,
    stride: int | None = None,
    start: float | None = None,
    end: float | None = None,
    max_frames: int | None = None,
    fps: int = FPS,
    width_px: int = 720,
) -> MovieInfo:
    """Write the movie of ``record`` to ``path`` (.mp4 or .gif).

    Through a temporary file, so a finished movie is never partial.

    Parameters
    ----------
    record : RunRecord
        The run (:class:`~skygas.outputs.records.RunRecord`).
    path : str or Path
        The movie file, ending in .mp4 or .gif, in an existing directory.
    stride : int, optional
        Every ``stride``-th recorded frame (default: the smallest stride that keeps at most
        ``max_frames``).
    start, end : float, optional
        The time span [s] to show (default: the whole record).
    max_frames : int, optional
        The most frames (default: 1200 for MP4, 300 for GIF).
    fps : int
        Frames per second.
    width_px : int
        The frame width [px].

    Returns
    -------
    MovieInfo
        What was written.

    Raises
    ------
    InputError
        If ``path`` has no known movie suffix or its directory is missing.
    """
    path = check_movie_path(path)
    suffix = path.suffix.lower()
    indices, stride = choose_frames(
        record.frames.time,
        stride=stride,
        start=start,
        end=end,
        max_frames=max_frames or MAX_FRAMES[suffix],
    )
    images = frame_images(record, indices, width_px)
    first = next(images)
    size = (first.shape[1], first.shape[0])

    def write(tmp: Path) -> None:  # a failed movie leaves no file behind
        if suffix == ".mp4":
            write_mp4(tmp, first, images, size, fps)
        else:
            _write_gif(tmp, first, images, fps)

    from skygas.runs.run_driver import write_atomic

    write_atomic(path, write)
    t = record.frames.time
    return MovieInfo(
        path,
        len(indices),
        stride,
        float(t[indices[0]]),
        float(t[indices[-1]]),
        fps,
        path.stat().st_size,
        size,
    )


def write_mp4(
    path: Path, first, images, size, fps: int, *, preset: str = "ultrafast", crf: int = 28
) -> None:
    """Encode RGB frames (``first``, then the iterable ``images``) as H.264 MP4 at ``path``.

    ``size`` (width, height) [px], whole multiples of 16; ``fps`` frames per second; the x264
    ``preset`` and constant rate factor ``crf`` (higher: smaller and coarser). A failure (a
    full disk) is one :class:`OSError` (:func:`skygas.runs.video.encode_mp4`).
    """
    import itertools

    from skygas.runs.video import encode_mp4

    # "ultrafast" encodes ~2x faster than "veryfast" for ~3x the bytes (~3.5 kB a frame of
    # this mostly still picture): the run-time budget binds, the size limit (20 MB) does not
    encode_mp4(path, itertools.chain([first], images), size, fps, preset=preset, crf=crf)


def _write_gif(path: Path, first, images, fps: int) -> None:
    from PIL import Image

    # one palette for the whole movie (from the first frame): no per-frame palette search
    palette = Image.fromarray(first).quantize(colors=64, method=Image.Quantize.MEDIANCUT)

    def quantized(image):
        return Image.fromarray(image).quantize(palette=palette, dither=Image.Dither.NONE)

    rest = [quantized(image) for image in images]
    quantized(first).save(
        path,
        format="GIF",
        save_all=True,
        append_images=rest,
        duration=round(1000 / fps),
        loop=0,
        optimize=False,
    )
