"""Device outlines: shapes, unions, named open ports, and the paper's chamber.

An :class:`Outline` is the region a skyrmion may occupy (a shapely polygon) plus named
**ports**: stretches of its boundary that are open rather than walls. Skyrmions feel the wall
force from every other part of the boundary; a skyrmion that crosses a port leaves the device.

The outline only describes *shape*. The force a wall exerts lives in :mod:`skygas.physics.forces`,
and the precomputed distance/normal grid the engine reads lives in :mod:`skygas.fields.wall_field`.

Everything public is in SI units: the constructors take metres, and the queries
(:meth:`Outline.contains`, :meth:`Outline.wall_distance`, :meth:`Outline.area`,
:attr:`Outline.bounds`) and :func:`random_positions` take and return metres. Sizes are given as
**diameters** (:func:`disk`, :func:`chamber_with_conduits`), as the device configurations give
them; rectangles by their sides. The outline stores nanometres internally (shapely's tolerances
assume coordinates of order one); the ``_nm`` forms of the queries are the engine's.
"""

from __future__ import annotations

import math
import warnings
from dataclasses import dataclass, field
from functools import cached_property

import numpy as np
import shapely
import shapely.validation
from shapely.geometry import LineString, MultiPolygon, Point, Polygon, box
from shapely.ops import unary_union

from skygas.core.config_types import (
    CHAMBER_DIAMETER,
    CONDUIT_LENGTH,
    CONDUIT_WIDTH,
    require_length,
)
from skygas.core.errors import InputError, require
from skygas.core.units import M_TO_NM

# Ports are matched against the boundary with this tolerance (nm).
_PORT_TOLERANCE_NM = 1e-6


@dataclass(frozen=True)
class Outline:
    """A device outline: the ``region`` a skyrmion may occupy and its open ``ports``.

    Its queries take and return metres (:meth:`contains`, :meth:`wall_distance`, :meth:`area`,
    :attr:`bounds`); the shapely shapes it holds are in nanometres, the engine's unit.
    ``region`` is a shapely Polygon, or a MultiPolygon for devices made of separate chambers
    (the reshuffler's UP and DOWN chambers). Build it with :func:`disk`, :func:`rectangle`,
    :func:`polygon`, :func:`union` and :meth:`with_port`, or :func:`chamber_with_conduits` for
    the paper's chamber.

    Parameters
    ----------
    region : shapely.Polygon or shapely.MultiPolygon
        The area a skyrmion may occupy [nm]; valid and not empty.
    ports : dict of str to shapely.LineString
        Named stretches of the boundary [nm] that are open rather than walls.

    Raises
    ------
    InputError
        If ``region`` is empty, not a (Multi)Polygon, or not valid (self-intersecting).
    """

    region: Polygon | MultiPolygon
    ports: dict[str, LineString] = field(default_factory=dict)

    def __post_init__(self):
        if not isinstance(self.region, (Polygon, MultiPolygon)) or self.region.is_empty:
            raise InputError("geometry", self.region, "a non-empty region of one or more pieces")
        if not self.region.is_valid:
            raise InputError(
                "geometry",
                shapely.validation.explain_validity(self.region),
                "a valid (non self-intersecting) outline",
            )

    # -- composition ------------------------------------------------------------------------
    def __or__(self, other: Outline) -> Outline:
        return union(self, other)

    def with_port(self, name: str, start, end) -> Outline:
        """Open the boundary segment from ``start`` to ``end`` (metres) as port ``name``.

        Parameters
        ----------
        name : str
            The port's name, not already used.
        start, end : tuple of float
            The segment's ends (x, y) [m]; the segment must lie on the boundary.

        Returns
        -------
        Outline
            A new outline with the port added.

        Raises
        ------
        InputError
            If the name is taken or the segment is not on the boundary.
        """
        segment = LineString([np.asarray(start) * M_TO_NM, np.asarray(end) * M_TO_NM])
        return self._with_port_nm(name, segment)

    def _with_port_nm(self, name: str, segment: LineString) -> Outline:
        require(name not in self.ports, "port name", name, "a name not already used")
        on_boundary = self.region.boundary.buffer(_PORT_TOLERANCE_NM).contains(segment)
        require(
            on_boundary,
            f"ports.{name}",
            list(segment.coords),
            "a segment lying on the outline's boundary",
        )
        return Outline(self.region, {**self.ports, name: segment})

    # -- queries (metres) -------------------------------------------------------------------
    @cached_property
    def walls(self):
        """The boundary minus the ports (a (Multi)LineString in nm, as :attr:`region`)."""
        boundary = self.region.boundary
        if not self.ports:
            return boundary
        openings = unary_union(list(self.ports.values())).buffer(_PORT_TOLERANCE_NM)
        return boundary.difference(openings)

    @property
    def bounds(self) -> tuple[float, float, float, float]:
        """(x0, y0, x1, y1) [m], the bounding box of the region."""
        x0, y0, x1, y1 = self.region.bounds
        return (x0 / M_TO_NM, y0 / M_TO_NM, x1 / M_TO_NM, y1 / M_TO_NM)

    def contains(self, x, y) -> np.ndarray:
        """Whether the points (x, y) [m] lie strictly inside the region.

        Parameters
        ----------
        x, y : float or array_like
            Coordinates [m] (broadcast against each other).

        Returns
        -------
        numpy.ndarray of bool
            True where the point is inside.
        """
        return self._contains_nm(np.asarray(x, float) * M_TO_NM, np.asarray(y, float) * M_TO_NM)

    def wall_distance(self, x, y) -> np.ndarray:
        """The exact distance [m] from the points (x, y) [m] to the nearest wall.

        Ports are not walls: a point near a port is as far from the walls as from the rest of
        the boundary.

        Parameters
        ----------
        x, y : float or array_like
            Coordinates [m].

        Returns
        -------
        numpy.ndarray
            The distance [m] (≥ 0, on either side of the wall).
        """
        nm = self._wall_distance_nm(np.asarray(x, float) * M_TO_NM, np.asarray(y, float) * M_TO_NM)
        return nm / M_TO_NM

    def area(self) -> float:
        """The area of the region [m²]."""
        return self._area_nm2() / M_TO_NM**2

    # -- the same queries in the engine's unit, nanometres ----------------------------------
    @property
    def _bounds_nm(self) -> tuple[float, float, float, float]:
        """(x0, y0, x1, y1) [nm], the bounding box of the region."""
        return tuple(self.region.bounds)

    def _contains_nm(self, x, y) -> np.ndarray:
        """True where (x, y) [nm] is strictly inside the region."""
        return shapely.contains_xy(self.region, np.asarray(x, float), np.asarray(y, float))

    def _wall_distance_nm(self, x, y) -> np.ndarray:
        """Exact distance [nm] from (x, y) [nm] to the nearest wall (shapely)."""
        points = shapely.points(np.asarray(x, float), np.asarray(y, float))
        return shapely.distance(points, self.walls)

    def _area_nm2(self) -> float:
        """The area of the region [nm²]."""
        return float(self.region.area)

    # -- the former public names, for one release ------------------------------------------
    @property
    def bounds_nm(self) -> tuple[float, float, float, float]:
        """Deprecated: :attr:`bounds` [m] × 10⁹."""
        _deprecated("bounds_nm", "bounds")
        return self._bounds_nm

    def contains_nm(self, x, y) -> np.ndarray:
        """Deprecated: :meth:`contains` of points in metres."""
        _deprecated("contains_nm", "contains")
        return self._contains_nm(x, y)

    def wall_distance_nm(self, x, y) -> np.ndarray:
        """Deprecated: :meth:`wall_distance` of points in metres."""
        _deprecated("wall_distance_nm", "wall_distance")
        return self._wall_distance_nm(x, y)

    def area_nm2(self) -> float:
        """Deprecated: :meth:`area` [m²] × 10¹⁸."""
        _deprecated("area_nm2", "area")
        return self._area_nm2()

    # -- composition and records ---------------------------------------------------------------
    def translated(self, dx: float, dy: float) -> Outline:
        """The same outline moved by (dx, dy) metres (port names kept)."""
        from shapely import affinity

        dx, dy = dx * M_TO_NM, dy * M_TO_NM
        return Outline(
            affinity.translate(self.region, dx, dy),
            {k: affinity.translate(v, dx, dy) for k, v in self.ports.items()},
        )

    def without_ports(self, *names: str) -> Outline:
        """The same outline with the named ports closed into walls."""
        for name in names:
            require(name in self.ports, "port name", name, f"one of {list(self.ports)}")
        return Outline(self.region, {k: v for k, v in self.ports.items() if k not in names})

    def port_names(self) -> list[str]:
        """The names of the open ports, in the order they were opened."""
        return list(self.ports)

    def describe(self) -> dict:
        """A JSON-able record of the outline (WKT in nm and the ports)."""
        return {
            "region_wkt_nm": self.region.wkt,
            "ports_nm": {k: [list(c) for c in v.coords] for k, v in self.ports.items()},
        }

    @classmethod
    def from_record(cls, record: dict) -> Outline:
        """The outline back from its :meth:`describe` record."""
        region = shapely.from_wkt(record["region_wkt_nm"])
        ports = {k: LineString(v) for k, v in record.get("ports_nm", {}).items()}
        return cls(region, ports)


def _deprecated(old: str, new: str) -> None:
    warnings.warn(
        f"Outline.{old} (nanometres) is deprecated and will be removed in the next release: "
        f"use Outline.{new}, in metres",
        DeprecationWarning,
        stacklevel=3,
    )


def _positive(name: str, value: float, device: bool = False) -> float:
    """``value`` if a finite length > 0; a ``device`` size also within 1 pm … 1 m.

    A disk or chamber of 800 is 800 nm given in the wrong unit ("did you mean 800e-9?"); a
    rectangle also serves as a box in other units (the periodic box of tracks in pixels).
    """
    require(
        isinstance(value, (int, float)) and value > 0 and math.isfinite(value),
        name,
        value,
        "a length > 0 in metres",
    )
    return require_length(name, float(value)) if device else float(value)


# Circles become polygons whose chords stray at most this far from the true circle (nm).
_CHORD_ERROR_NM = 0.05


def _circle_segments(radius_nm: float) -> int:
    """Segments per quarter circle so that the chord error R(1 − cos θ/2) ≤ _CHORD_ERROR_NM."""
    return max(8, int(math.ceil(math.pi / 4 * math.sqrt(radius_nm / (2 * _CHORD_ERROR_NM)))))


def _circle(cx: float, cy: float, r: float) -> Polygon:
    return Point(cx, cy).buffer(r, quad_segs=_circle_segments(r))


def disk(*, diameter: float, center=(0.0, 0.0)) -> Outline:
    """A disk of ``diameter`` [m] at ``center`` [m] (a polygon within 0.05 nm of the circle).

    Sizes are diameters throughout skygas, as in :func:`chamber_with_conduits` and the
    configurations (``chamber_diameter``, ``skyrmion_diameter``); the keyword is required, so
    that a radius cannot be passed by mistake.

    Parameters
    ----------
    diameter : float
        The diameter 2R [m], > 0.
    center : tuple of float
        (x, y) of the centre [m].

    Returns
    -------
    Outline
        The disk, without ports.

    Raises
    ------
    InputError
        If ``diameter`` is not a finite length > 0.

    Examples
    --------
    >>> import skygas
    >>> round(skygas.disk(diameter=1e-6).area() * 1e12, 3)  # π (0.5 µm)² in µm²
    0.785
    """
    r = _positive("diameter", diameter, device=True) / 2 * M_TO_NM
    cx, cy = np.asarray(center, float) * M_TO_NM
    return Outline(_circle(cx, cy, r))


def rectangle(width: float, height: float, center=(0.0, 0.0)) -> Outline:
    """An axis-aligned rectangle of ``width`` × ``height`` [m] centred at ``center`` [m].

    Parameters
    ----------
    width, height : float
        The sides along x and y [m], > 0.
    center : tuple of float
        (x, y) of the centre [m].

    Returns
    -------
    Outline
        The rectangle, without ports.

    Raises
    ------
    InputError
        If a side is not a finite length > 0.
    """
    w = _positive("width", width) * M_TO_NM
    h = _positive("height", height) * M_TO_NM
    cx, cy = np.asarray(center, float) * M_TO_NM
    return Outline(box(cx - w / 2, cy - h / 2, cx + w / 2, cy + h / 2))


def polygon(vertices) -> Outline:
    """A polygon through ``vertices`` [m].

    Parameters
    ----------
    vertices : array_like
        (n, 2) points (x, y) [m], n ≥ 3, in order along the boundary.

    Returns
    -------
    Outline
        The polygon, without ports.

    Raises
    ------
    InputError
        If there are fewer than three (x, y) points, or the polygon intersects itself.
    """
    v = np.asarray(vertices, float)
    require(
        v.ndim == 2 and v.shape[1] == 2 and len(v) >= 3,
        "vertices",
        vertices,
        "at least three (x, y) points in metres",
    )
    return Outline(Polygon(v * M_TO_NM))


def union(*outlines: Outline) -> Outline:
    """The union of overlapping outlines (ports are kept).

    Parameters
    ----------
    *outlines : Outline
        Shapes that overlap into one connected region.

    Returns
    -------
    Outline
        One region, with the ports of every outline.

    Raises
    ------
    InputError
        If the union falls apart into disjoint pieces, or a port name is used twice.
    """
    region = unary_union([o.region for o in outlines])
    if not isinstance(region, Polygon):
        raise InputError(
            "geometry",
            f"{len(getattr(region, 'geoms', []))} disjoint pieces",
            "shapes that overlap into one connected region",
        )
    result = Outline(region)
    for o in outlines:
        for name, seg in o.ports.items():
            result = result._with_port_nm(name, seg)
    return result


def chamber_with_conduits(
    chamber_diameter: float = CHAMBER_DIAMETER,
    conduit_width: float = CONDUIT_WIDTH,
    conduit_length: float = CONDUIT_LENGTH,
    center=(0.0, 0.0),
    corner_radius: float = 20e-9,
) -> Outline:
    """The paper's device chamber: a disk with an input and an output conduit along the x axis.

    The input conduit is on the left, the output conduit on the right (paper, "Skyrmion Reshuffler"
    and Methods). The open ends are the ports ``"input"`` (left) and ``"output"`` (right).

    The four re-entrant corners where the conduits meet the disk are rounded with
    ``corner_radius`` [m] (0 keeps them sharp). A sharp re-entrant corner makes the current
    density diverge there (as r^(−1/3)), and the drift then drives skyrmions into the wall
    faster than the wall law can push them back; lithographed devices have rounded corners.

    Parameters
    ----------
    chamber_diameter : float
        The disk's diameter [m].
    conduit_width : float
        The conduits' width [m], smaller than the diameter.
    conduit_length : float
        Measured from where the conduit's edges meet the disk to its open end [m].
    center : tuple of float
        The disk's centre [m].
    corner_radius : float
        Radius [m] of the rounded corners where the conduits meet the disk (0: sharp).

    Returns
    -------
    Outline
        One region with the ports ``"input"`` and ``"output"``.

    Raises
    ------
    InputError
        If a length is not > 0, the conduit is not narrower than the chamber, or ``corner_radius``
        is negative.
    """
    d = _positive("chamber_diameter", chamber_diameter, device=True)
    w = _positive("conduit_width", conduit_width, device=True)
    length = _positive("conduit_length", conduit_length, device=True)
    require(w < d, "conduit_width", w, f"a width smaller than the chamber diameter ({d} m)")
    r = d / 2 * M_TO_NM
    half_w = w / 2 * M_TO_NM
    cx, cy = np.asarray(center, float) * M_TO_NM
    # x where the conduit edges (y = ±w/2) meet the circle; the conduit overlaps the disk
    # from there to a little past it, so the union is one region.
    x_meet = math.sqrt(r * r - half_w * half_w)
    x_end = x_meet + length * M_TO_NM
    chamber = _circle(cx, cy, r)
    overlap = 0.5 * (r - x_meet) + 1.0
    left = box(cx - x_end, cy - half_w, cx - x_meet + overlap, cy + half_w)
    right = box(cx + x_meet - overlap, cy - half_w, cx + x_end, cy + half_w)
    region = unary_union([chamber, left, right])
    require(
        corner_radius >= 0 and math.isfinite(corner_radius),
        "corner_radius",
        corner_radius,
        "a radius >= 0 in metres",
    )
    if corner_radius > 0:
        # A closing (grow, then shrink) fills re-entrant corners with arcs. Only its material
        # near the four junctions is added, so every other vertex (the conduit ends with
        # their ports) stays exactly where it was.
        rad = corner_radius * M_TO_NM
        segs = _circle_segments(rad)
        closed = region.buffer(rad, quad_segs=segs, join_style="mitre").buffer(
            -rad, quad_segs=segs, join_style="round"
        )
        junctions = unary_union(
            [
                Point(cx + sx * x_meet, cy + sy * half_w).buffer(3 * rad)
                for sx in (-1, 1)
                for sy in (-1, 1)
            ]
        )
        region = unary_union([region, closed.intersection(junctions)])
    outline = Outline(region)
    outline = outline._with_port_nm(
        "input", LineString([(cx - x_end, cy - half_w), (cx - x_end, cy + half_w)])
    )
    return outline._with_port_nm(
        "output", LineString([(cx + x_end, cy - half_w), (cx + x_end, cy + half_w)])
    )


def random_positions(
    outline: Outline,
    count: int,
    min_separation: float,
    min_wall_distance: float,
    rng: np.random.Generator,
    max_tries: int = 200_000,
    occupied: np.ndarray | None = None,
) -> np.ndarray:
    """``count`` random points [m] inside ``outline``, by random sequential addition.

    Parameters
    ----------
    outline : Outline
        Where the points lie.
    count : int
        How many points.
    min_separation : float
        Their least distance [m] from each other and from the ``occupied`` points.
    min_wall_distance : float
        Their least distance [m] from the walls.
    rng : numpy.random.Generator
        The source of randomness (the same generator state gives the same points).
    max_tries : int
        Candidate points tried before giving up.
    occupied : array_like, optional
        (n, 2) points [m] already taken (not returned).

    Returns
    -------
    numpy.ndarray
        (count, 2) points (x, y) [m].

    Raises
    ------
    InputError
        If the points do not fit (more than ``max_tries`` tries).
    """
    taken = None if occupied is None else np.asarray(occupied, float).reshape(-1, 2) * M_TO_NM
    points = _random_positions_nm(
        outline,
        count,
        min_separation * M_TO_NM,
        min_wall_distance * M_TO_NM,
        rng,
        max_tries=max_tries,
        occupied=taken,
    )
    return points / M_TO_NM


def _random_positions_nm(
    outline: Outline,
    count: int,
    min_separation_nm: float,
    min_wall_distance_nm: float,
    rng: np.random.Generator,
    max_tries: int = 200_000,
    occupied: np.ndarray | None = None,
) -> np.ndarray:
    """:func:`random_positions` in the engine's unit: every length and point in nm."""
    x0, y0, x1, y1 = outline._bounds_nm
    held = 0 if occupied is None else len(occupied)
    points = np.empty((0, 2)) if occupied is None else np.asarray(occupied, float).reshape(-1, 2)
    total = count + held
    tries = 0
    while len(points) < total:
        batch = rng.uniform((x0, y0), (x1, y1), size=(256, 2))
        inside = outline._contains_nm(batch[:, 0], batch[:, 1])
        batch = batch[inside]
        if len(batch):
            far = outline._wall_distance_nm(batch[:, 0], batch[:, 1]) >= min_wall_distance_nm
            batch = batch[far]
        for p in batch:
            tries += 1
            if len(points) == 0 or np.min(np.hypot(*(points - p).T)) >= min_separation_nm:
                points = np.vstack([points, p])
                if len(points) == total:
                    break
        tries += 1
        if tries > max_tries:
            raise InputError(
                "skyrmions.count",
                count,
                f"fewer skyrmions: only {len(points) - held} fit at "
                f"{min_separation_nm * 1e-9:.3g} m separation",
            )
    return points[held:]
