"""The movies' frames can be read: nothing floats over the data, and the scale bars are right.

Each frame of ``skygas animate`` and of ``skygas track``'s overlay is painted onto a static
picture drawn once with matplotlib; that figure is checked with the layout test of every figure
(:func:`~tests.outputs.figure_layout.layout_faults`), and beyond it: the legend, the scale bar
and the time stamp lie outside the chamber (or the movie's picture), and a scale bar's label
states the length it is drawn at (measured on the drawn bar, in display pixels).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.transforms import Bbox
from tests.outputs.figure_layout import layout_faults

ROOT = Path(__file__).resolve().parents[2]
SHIPPED = ROOT / "examples" / "tracking" / "chamber-movie.tif"
_PREFIX = {"nm": 1e-9, "µm": 1e-6, "mm": 1e-3, "m": 1.0}


def _renderer(fig):
    return FigureCanvasAgg(fig).get_renderer()


def _apart(a: Bbox, b: Bbox) -> bool:
    """The two boxes share no area (a pixel of rounding allowed)."""
    return min(a.x1, b.x1) - max(a.x0, b.x0) <= 1 or min(a.y1, b.y1) - max(a.y0, b.y0) <= 1


def _bar(scale_bar, renderer) -> tuple[str, float]:
    """A scale bar's label and the length [display px] of the bar drawn."""
    (rectangle,) = scale_bar.size_bar.get_children()
    label = scale_bar.txt_label.get_children()[0].get_text()
    return label, rectangle.get_window_extent(renderer).width


def _stamp_box(canvas_height: int, xy, text: str, size: int) -> Bbox:
    """Where Pillow paints ``text`` at ``xy`` (rows from the top), in display pixels."""
    from PIL import Image, ImageDraw

    from skygas.outputs.movie import font

    left, top, right, bottom = ImageDraw.Draw(Image.new("RGB", (1, 1))).textbbox(
        xy, text, font=font(size)
    )
    return Bbox.from_extents(left, canvas_height - bottom, right, canvas_height - top)


# -- the overlay of skygas track -----------------------------------------------------------------
@pytest.mark.parametrize(
    ("pixel_size", "label", "metres"),
    [(14e-9, "200 nm", 200e-9), (0.5e-6, "10 µm", 10e-6), (None, "20 px", None)],
)
def test_the_overlay_frame_has_a_scale_bar_of_its_stated_length_below_the_picture(
    pixel_size, label, metres
):
    from skygas.movies.overlay import STAMP_PX, OverlayCanvas

    shape, scale = (80, 86), 4  # the shipped movie's frames, drawn 4 times larger
    canvas = OverlayCanvas(shape, scale, pixel_size)
    fig = canvas.figure
    assert layout_faults(fig) == []
    renderer = _renderer(fig)
    bars = [a for a in fig.artists if a is canvas.scale_bar]
    assert len(bars) == 1
    text, drawn = _bar(bars[0], renderer)
    assert text == label
    # the label's length, in movie pixels, times the scale: the bar's drawn length
    pixels = 20 if metres is None else metres / pixel_size
    assert drawn == pytest.approx(pixels * scale, abs=1.0)
    picture = canvas.axes.get_window_extent(renderer)
    assert picture.width == shape[1] * scale and picture.height == shape[0] * scale
    bar_box = bars[0].get_window_extent(renderer)
    assert _apart(bar_box, picture) and bar_box.y1 <= picture.y0 + 1  # below the picture
    # the longest stamp of a 1200-frame overlay stays in the strip, clear of the bar
    stamp = _stamp_box(canvas.image.shape[0], canvas.stamp_xy, canvas.stamp(1199, 2e-9), STAMP_PX)
    assert _apart(stamp, bar_box) and _apart(stamp, picture)
    assert stamp.y0 >= 0 and stamp.x1 <= canvas.image.shape[1]


def test_the_painted_overlay_frame_keeps_the_scale_bar_and_the_picture_in_place():
    import pandas as pd
    import tifffile
    from PIL import Image

    from skygas.movies.overlay import OverlayCanvas, overlay_frames
    from skygas.movies.tracking import Tracks

    class Movie:  # the first three frames of the shipped movie, as skygas.movies.reading serves
        stack = tifffile.imread(SHIPPED, key=range(3))
        shape = stack.shape[1:]
        n_frames = 3

        def frame(self, i):
            return self.stack[i].astype(float)

    table = pd.DataFrame(
        {"frame": [0, 1, 2], "particle": [0, 0, 0], "x": [0.0, 1.0, 2.0], "y": [40.0] * 3}
    )
    image = next(overlay_frames(Movie(), Tracks(table), 7, [2], pixel_size=14e-9))
    canvas = OverlayCanvas(Movie.shape, 4, 14e-9)
    assert image.shape == canvas.image.shape and image.shape[0] % 16 == image.shape[1] % 16 == 0
    renderer = _renderer(canvas.figure)
    height = image.shape[0]
    bar = canvas.scale_bar.get_window_extent(renderer)
    rows = slice(int(height - bar.y1), int(np.ceil(height - bar.y0)))
    cols = slice(int(bar.x0), int(np.ceil(bar.x1)))
    # the bar and its label are painted in every frame, as drawn on the figure
    assert np.array_equal(image[rows, cols], canvas.image[rows, cols])
    assert image[rows, cols].min() < 100  # dark ink on white
    # the circle of a skyrmion at the left edge is cut at the picture's edge: the margin stays
    x0, y0 = canvas.picture_xy
    assert np.all(image[:, : x0 - 1] == 255)
    # and the picture is the movie's frame, scaled, where no circle is drawn
    picture = Image.fromarray(image[y0 + 4 * 60 : y0 + 4 * 80, x0 + 4 * 43 : x0 + 4 * 86, 0])
    frame = Movie().stack[2, 60:80, 43:86]
    lo, hi = np.percentile(Movie().stack[0], [0.5, 99.5])
    grey = np.clip((frame - lo) / (hi - lo) * 255, 0, 255).astype(np.uint8)
    assert np.array_equal(np.asarray(picture)[::4, ::4], grey)


# -- the frames of skygas animate ----------------------------------------------------------------
def _record(kind: str):
    """A run record (no simulation needed): the device, a few skyrmions, groups, a background."""
    from skygas.analysis.frames import Frames
    from skygas.outputs.records import RunRecord
    from skygas.physics.geometry import rectangle

    if kind == "reshuffler":
        from skygas.reshuffler.device import ReshufflerGeometry

        outline = ReshufflerGeometry(1024e-9, 100e-9, 50e-9, 400e-9).device_outline()
        names = ("input bit 1 (to UP)", "input bit 0 (to DOWN)", "unknown")
    else:
        outline = rectangle(700e-9, 700e-9)
        names = ("skyrmions",)
    x0, y0, x1, y1 = np.array(outline._bounds_nm) * 1e-9
    rng = np.random.default_rng(1)
    xy = rng.uniform((x0, y0), (x1, y1), (200, 2))
    xy = xy[outline._contains_nm(xy[:, 0] * 1e9, xy[:, 1] * 1e9)][:12]
    frames = Frames(np.array([0.0]), np.array([len(xy)]), np.arange(len(xy)), xy[:, 0], xy[:, 1])

    def background(x, y):  # a current density over three decades, as the reshuffler's
        return 1e8 + 1e11 * np.hypot(x - x0, y - y0) / np.hypot(x1 - x0, y1 - y0), "|j| (A/m²)"

    return RunRecord(
        kind,
        Path("run.nc"),
        frames,
        outline,
        40e-9,
        names,
        lambda ids, x, y: np.asarray(ids) % len(names),
        None,
        {},
        "0",
        0,
        background_fn=background if kind == "reshuffler" else None,
    )


@pytest.mark.parametrize("kind", ["reshuffler", "chamber"])
@pytest.mark.parametrize("width", [720, 480])
def test_the_animate_frame_keeps_legend_scale_bar_and_stamp_off_the_device(kind, width):
    from skygas.outputs.movie import _Canvas, _time_label

    record = _record(kind)
    canvas = _Canvas(record, width)
    fig = canvas.figure
    assert layout_faults(fig) == []
    renderer = _renderer(fig)
    chamber = canvas.axes.get_window_extent(renderer)
    assert (canvas.legend is not None) == (kind == "reshuffler")
    boxes = {"scale bar": canvas.scale_bar.get_window_extent(renderer)}
    if canvas.legend is not None:
        boxes["legend"] = canvas.legend.get_window_extent(renderer)
    # the time stamp painted on each frame: the longest one a run of microseconds shows
    boxes["stamp"] = _stamp_box(
        canvas.height, canvas.stamp_xy, f"{_time_label(9.999e-6)}   N = 1000", 15
    )
    for name, box in boxes.items():
        assert _apart(box, chamber), f"the {name} lies over the device"
        assert box.x0 >= 0 and box.x1 <= canvas.width and box.y0 >= 0, name
        assert box.y1 <= canvas.height, name
    names = list(boxes)
    for i, a in enumerate(names):
        for b in names[i + 1 :]:
            assert _apart(boxes[a], boxes[b]), f"the {a} and the {b} overlap"
    label, drawn = _bar(canvas.scale_bar, renderer)
    value, unit = label.split()
    assert drawn == pytest.approx(float(value) * _PREFIX[unit] * 1e6 * canvas.px_per_um, abs=1.0)
    assert canvas.height <= 1024 and canvas.height % 16 == canvas.width % 16 == 0


# -- the figures of skygas track -----------------------------------------------------------------
def test_the_track_figures_have_no_layout_fault(tmp_path, monkeypatch):
    import tifffile
    from matplotlib.figure import Figure

    from skygas.movies.track_run import track_movie

    found: dict[str, list[str]] = {}
    save = Figure.savefig

    def savefig(self, fname, *args, **kwargs):
        # write_figure saves to ".NAME.partial.png" first: the name is NAME.png
        found[Path(str(fname)).name.lstrip(".").replace(".partial", "")] = layout_faults(self)
        return save(self, fname, *args, **kwargs)

    monkeypatch.setattr(Figure, "savefig", savefig)
    movie = tmp_path / "good.tif"
    tifffile.imwrite(movie, tifffile.imread(SHIPPED, key=range(8)), photometric="minisblack")
    track_movie(movie, tmp_path / "out", pixel_size=14e-9, progress=False)
    assert found == {"detections.png": [], "track_lengths.png": []}
