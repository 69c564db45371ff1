"""The reservoir's chamber.

A confined outline whose contacts are electrodes for the current and walls for the skyrmions.

Shapes (``ChamberSpec.shape``), all centred on the origin:

- ``triangle``: equilateral, side ``size``, corners A (bottom left), B (bottom right), C (top);
- ``square``: side ``size``, corners A (bottom left), B (bottom right), C (top right),
  D (top left);
- ``disk``: diameter ``size`` with three flats A, B, C where the triangle's corners would be
  (at 210°, 330° and 90°);
- ``polygon``: the convex or concave ``vertices``, contacts named A, B, C, … in vertex order.

Each corner is cut by a straight contact of width ``contact_width`` (a port of the outline,
:meth:`~skygas.physics.geometry.Outline.with_port`); explicit ``contacts`` replace the cuts. The
current solver uses the ports as electrodes; the engine gets the same outline with every port closed
(:meth:`~skygas.physics.geometry.Outline.without_ports`), so that a skyrmion is reflected by a
contact like by any wall instead of leaving through it.
"""

from __future__ import annotations

import math
import string

import numpy as np

from skygas.core.errors import InputError, require
from skygas.core.units import M_TO_NM
from skygas.physics import geometry as geo
from skygas.reservoir.config import ChamberSpec


def _names(n: int) -> list[str]:
    return list(string.ascii_uppercase[:n])


def _regular(n: int, side: float, first_angle: float) -> np.ndarray:
    """Corners [m] of a regular n-gon of side ``side`` centred on the origin."""
    radius = side / (2 * math.sin(math.pi / n))
    angles = first_angle + 2 * math.pi * np.arange(n) / n
    return radius * np.column_stack([np.cos(angles), np.sin(angles)])


def _cut_corners(vertices: np.ndarray, width: float) -> tuple[np.ndarray, list]:
    """The polygon with every corner cut by a segment of length ``width`` [m].

    Returns the new vertices and the (start, end) of each cut.
    """
    n = len(vertices)
    points, cuts = [], []
    for k in range(n):
        p, prev, nxt = vertices[k], vertices[k - 1], vertices[(k + 1) % n]
        u, v = prev - p, nxt - p
        lu, lv = np.hypot(*u), np.hypot(*v)
        cos_angle = float(np.dot(u, v) / (lu * lv))
        half = 0.5 * math.acos(max(-1.0, min(1.0, cos_angle)))
        reach = width / (2 * math.sin(half)) if half > 0 else math.inf
        require(
            reach < 0.5 * min(lu, lv),
            "chamber.contact_width",
            width,
            f"a width that leaves part of every side (at most "
            f"{2 * math.sin(half) * 0.5 * min(lu, lv):.3g} m at corner {k})",
        )
        a, b = p + reach * u / lu, p + reach * v / lv
        points += [a, b]
        cuts.append((a, b))
    return np.array(points), cuts


def _disk_with_flats(diameter: float, width: float) -> geo.Outline:
    """A disk with straight flats of length ``width`` [m] centred at 210°, 330° and 90°.

    The flats' ends lie exactly on the circle, the arcs between them are polygons whose chords
    stray at most 0.05 nm from the circle (like :func:`skygas.physics.geometry.disk`).
    """
    radius = diameter / 2
    require(
        width < diameter,
        "chamber.contact_width",
        width,
        f"a width smaller than the disk's diameter ({diameter} m)",
    )
    half = math.asin(width / diameter)  # half the angle a flat spans
    step = 2 * math.sqrt(2 * 0.05 / (radius * M_TO_NM))  # chord error ≤ 0.05 nm
    centres = np.radians([90.0, 210.0, 330.0])
    points, cuts = [], []
    for k, centre in enumerate(centres):
        start, end = centre - half, centre + half
        cuts.append(
            (
                radius * np.array([math.cos(start), math.sin(start)]),
                radius * np.array([math.cos(end), math.sin(end)]),
            )
        )
        following = centres[(k + 1) % 3] + (2 * math.pi if k == 2 else 0.0) - half
        n = max(8, int(math.ceil((following - end) / step)))
        arc = np.linspace(end, following, n + 1)[:-1]  # from the flat's end, not the next start
        points.append(cuts[-1][0])
        points += [radius * np.array([math.cos(t), math.sin(t)]) for t in arc]
    outline = geo.polygon(np.array(points))
    for name, k in (("A", 1), ("B", 2), ("C", 0)):  # the flats at 210°, 330°, 90°
        outline = outline.with_port(name, *cuts[k])
    return outline


def build_chamber(spec: ChamberSpec) -> geo.Outline:
    """The chamber outline with its contacts as ports (see the module docstring)."""
    if spec.shape == "disk":
        outline = _disk_with_flats(spec.size, spec.contact_width)
        corners = None
    else:
        if spec.shape == "triangle":
            corners = _regular(3, spec.size, math.radians(210))
        elif spec.shape == "square":
            corners = _regular(4, spec.size, math.radians(225))
        else:
            require(
                len(spec.vertices) >= 3,
                "chamber.vertices",
                spec.vertices,
                "at least three (x, y) corners in metres for a polygon chamber",
            )
            corners = np.asarray(spec.vertices, float)
        if spec.contacts:
            outline = geo.polygon(corners)
        else:
            cut, cuts = _cut_corners(corners, spec.contact_width)
            outline = geo.polygon(cut)
            for name, (a, b) in zip(_names(len(cuts)), cuts, strict=True):
                outline = outline.with_port(name, a, b)
    if spec.contacts:
        outline = geo.Outline(outline.region)
        for k, c in enumerate(spec.contacts):
            try:
                outline = outline.with_port(c.name, c.start, c.end)
            except InputError:
                raise InputError(
                    f"chamber.contacts[{k}]",
                    [list(c.start), list(c.end)],
                    "a segment lying on the chamber's outline (contacts off the "
                    "outline cannot carry current)",
                ) from None
    return outline


def contact_middles(outline: geo.Outline) -> dict[str, np.ndarray]:
    """The middle [m] of each contact."""
    return {
        name: np.asarray(seg.interpolate(0.5, normalized=True).coords[0]) / M_TO_NM
        for name, seg in outline.ports.items()
    }
