"""What a readable figure needs, checked on the drawn canvas: the layout faults of a figure.

:func:`layout_faults` draws a figure and lists, in words, every text drawn over another text,
outside the figure or over another panel; every inset that covers the data or labels of the
panel it sits in; every legend that covers its panel's data; every labelled line with no point
inside its panel (a reference drawn outside the axis); and every colour image with no colour bar
for its colour scale.
"""

from __future__ import annotations

import numpy as np
from matplotlib.axes import Axes
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.collections import LineCollection, PathCollection
from matplotlib.figure import Figure
from matplotlib.image import AxesImage
from matplotlib.lines import Line2D
from matplotlib.text import Text
from matplotlib.transforms import Bbox
from shapely.geometry import Polygon
from shapely.geometry import box as shapely_box

#: Overlaps smaller than this (pixels, each way) are rounding, not a fault.
SLACK = 1.0


def _all_axes(fig: Figure) -> list[Axes]:
    """Every axes of the figure, parents before the insets they hold."""
    found: list[Axes] = []

    def visit(ax: Axes) -> None:
        found.append(ax)
        for child in ax.child_axes:
            visit(child)

    for ax in fig.axes:
        if ax not in found:
            visit(ax)
    return found


def _drawn_texts(fig: Figure):
    """Draw the figure; the Text artists the renderer was asked to draw, and the renderer."""
    canvas = fig.canvas
    renderer = FigureCanvasAgg(fig).get_renderer()
    fig.set_canvas(canvas)  # the figure keeps its own canvas (pyplot's, or a file's)
    drawn: dict[int, Text] = {}
    draw_text = renderer.draw_text

    def recording(gc, x, y, s, prop, angle, ismath=False, mtext=None):
        if mtext is not None and s.strip():
            drawn[id(mtext)] = mtext
        return draw_text(gc, x, y, s, prop, angle, ismath=ismath, mtext=mtext)

    renderer.draw_text = recording  # type: ignore[method-assign]
    fig.draw(renderer)
    return list(drawn.values()), renderer


def _overlap(a: Bbox, b: Bbox) -> bool:
    return min(a.x1, b.x1) - max(a.x0, b.x0) > SLACK and min(a.y1, b.y1) - max(a.y0, b.y0) > SLACK


def _outline(text: Text, renderer) -> Polygon:
    """The rectangle a text covers, turned with it (its window extent is the upright box around
    that rectangle, which for slanted tick labels would overlap its neighbours' boxes)."""
    box = text.get_window_extent(renderer)
    angle = np.deg2rad(text.get_rotation())
    if abs(np.sin(2 * angle)) < 1e-9:  # upright or on its side: the box is the rectangle
        return shapely_box(box.x0, box.y0, box.x1, box.y1)
    rotation = text.get_rotation()
    text.set_rotation(0)
    try:
        upright = text.get_window_extent(renderer)
    finally:
        text.set_rotation(rotation)
    w, h = upright.width / 2, upright.height / 2
    c, s = np.cos(angle), np.sin(angle)
    corners = [(x * c - y * s, x * s + y * c) for x, y in ((-w, -h), (w, -h), (w, h), (-w, h))]
    cx, cy = (box.x0 + box.x1) / 2, (box.y0 + box.y1) / 2
    return Polygon([(cx + x, cy + y) for x, y in corners])


def _meet(a: Polygon, b: Polygon) -> bool:
    return a.intersection(b).area > SLACK * SLACK * 4


def _inside(inner: Bbox, outer: Bbox) -> bool:
    return (
        inner.x0 >= outer.x0 - SLACK
        and inner.y0 >= outer.y0 - SLACK
        and inner.x1 <= outer.x1 + SLACK
        and inner.y1 <= outer.y1 + SLACK
    )


def _within(points: np.ndarray, box: Bbox) -> np.ndarray:
    """Which of the display points lie in ``box`` (edges included)."""
    return (
        (points[:, 0] >= box.x0)
        & (points[:, 0] <= box.x1)
        & (points[:, 1] >= box.y0)
        & (points[:, 1] <= box.y1)
    )


def _along(xy: np.ndarray, step: float = 4.0) -> np.ndarray:
    """Points every ``step`` pixels along a drawn polyline (display coordinates)."""
    out = [xy[:1]]
    for a, b in zip(xy[:-1], xy[1:], strict=True):
        if not (np.all(np.isfinite(a)) and np.all(np.isfinite(b))):
            continue
        n = int(min(np.hypot(*(b - a)) // step, 1000)) + 1
        out.append(a + np.linspace(0, 1, n + 1)[1:, None] * (b - a))
    return np.concatenate(out)


def _data_points(ax: Axes) -> np.ndarray:
    """The display coordinates of the panel's own lines and markers (not its insets')."""
    points = []
    for artist in ax.get_children():
        if isinstance(artist, Line2D) and artist.get_visible():
            xy = artist.get_xydata()
            if len(xy):
                xy = artist.get_transform().transform(np.asarray(xy, float))
                if artist.get_linestyle() not in ("None", "", " ") and len(xy) > 1:
                    xy = _along(xy)
                points.append(xy)
        elif isinstance(artist, PathCollection) and artist.get_visible():  # markers
            offsets = artist.get_offsets()
            if len(offsets):
                points.append(artist.get_offset_transform().transform(offsets))
        elif isinstance(artist, LineCollection) and artist.get_visible():  # error bars
            for segment in artist.get_segments():
                if len(segment):
                    points.append(artist.get_transform().transform(np.asarray(segment, float)))
    points = [p[np.all(np.isfinite(p), axis=1)] for p in points]
    return np.concatenate(points) if points else np.empty((0, 2))


def layout_faults(fig: Figure) -> list[str]:
    """The layout faults of ``fig``, one sentence each (empty: none found).

    - two drawn texts overlap (tick labels, axis labels, titles, legends, annotations);
    - a text reaches outside the figure;
    - a text of one panel lies over another panel (a colour bar included);
    - an inset covers a text outside it, another panel, or a point of its parent's data;
    - a legend covers a point of its panel's data (a line's vertex or a marker);
    - a line with a legend label has no point inside its panel (a reference off the axis);
    - an image coloured by a colour scale has no colour bar for that scale.
    """
    texts, renderer = _drawn_texts(fig)
    axes = _all_axes(fig)
    owner: dict[int, Axes | None] = {}
    for ax in axes:  # parents first: an inset's texts end up its own
        for artist in ax.findobj(Text):
            owner[id(artist)] = ax
    shapes = [(t, _outline(t, renderer)) for t in texts]
    boxes = [(t, Bbox.from_extents(*shape.bounds)) for t, shape in shapes]
    frame = fig.bbox
    faults = []

    def name(t: Text) -> str:
        return repr(t.get_text()[:40])

    for i, (t, shape) in enumerate(shapes):
        if not _inside(boxes[i][1], frame):
            faults.append(f"text {name(t)} reaches outside the figure")
        for u, other in shapes[i + 1 :]:
            if _meet(shape, other):
                faults.append(f"texts {name(t)} and {name(u)} overlap")
        mine = owner.get(id(t))
        for ax in axes:
            panel = ax.get_window_extent(renderer)
            if ax is not mine and _meet(shape, shapely_box(panel.x0, panel.y0, panel.x1, panel.y1)):
                faults.append(f"text {name(t)} lies over another panel")
    for parent in axes:
        for inset in parent.child_axes:
            if not inset.get_visible():
                continue
            area = inset.get_window_extent(renderer)
            for t, box in boxes:
                if owner.get(id(t)) is not inset and _overlap(area, box):
                    faults.append(f"an inset covers the text {name(t)}")
            for ax in axes:
                if ax not in (inset, parent) and ax not in inset.child_axes:
                    if _overlap(area, ax.get_window_extent(renderer)):
                        faults.append("an inset covers another panel")
            covered = _within(_data_points(parent), area.padded(-SLACK))
            if covered.any():
                faults.append(f"an inset covers {int(covered.sum())} points of its panel's data")
    for ax in axes:
        legend = ax.get_legend()
        if legend is not None and legend.get_visible():
            points = _data_points(ax)
            points = points[_within(points, ax.get_window_extent(renderer))]  # those drawn
            covered = _within(points, legend.get_window_extent(renderer).padded(-SLACK))
            if covered.any():
                faults.append(f"a legend covers {int(covered.sum())} points of its panel's data")
    for ax in axes:
        panel = ax.get_window_extent(renderer).padded(SLACK)
        for line in ax.get_lines():
            if not line.get_visible() or line.get_label().startswith("_"):
                continue
            xy = line.get_transform().transform(np.asarray(line.get_xydata(), float))
            xy = xy[np.all(np.isfinite(xy), axis=1)]
            if len(xy) and not np.any(_within(xy, panel)):
                faults.append(f"the line {line.get_label()!r} lies outside its panel")
    barred = [
        (m.get_cmap().name, m.norm.vmin, m.norm.vmax)
        for ax in axes
        for m in [*ax.images, *ax.collections]
        if getattr(m, "colorbar", None) is not None
    ]
    for ax in axes:
        for image in ax.images:
            if not isinstance(image, AxesImage) or not image.get_visible():
                continue
            data = image.get_array()
            if data is None or np.ma.count(data) == 0 or np.ndim(data) != 2:
                continue  # an RGB picture has no colour scale
            if (image.get_cmap().name, image.norm.vmin, image.norm.vmax) not in barred:
                faults.append("an image has no colour bar for its colour scale")
    return faults
