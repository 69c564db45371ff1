"""Device outlines, ports, the precomputed wall field and random placement.

Constructors take metres; outlines and wall fields work in nanometres. Expected distances are
the analytic ones of the ideal shapes (circle, rectangle).
"""

import math

import numpy as np
import pytest
import shapely

from skygas.core.errors import InputError
from skygas.fields.wall_field import Grid, WallField
from skygas.physics.geometry import (
    Outline,
    _random_positions_nm,
    chamber_with_conduits,
    disk,
    polygon,
    random_positions,
    rectangle,
    union,
)

D_SK_NM = 38.2
SPACING_NM = D_SK_NM / 16  # the engine's default grid spacing


# -- the paper's chamber ------------------------------------------------------------------------
@pytest.mark.parametrize(
    "diameter, width, length, center",
    [
        (1024e-9, 100e-9, 50e-9, (0.0, 0.0)),
        (400e-9, 60e-9, 120e-9, (1e-6, -2e-7)),
    ],
)
def test_chamber_ports_sit_at_the_conduit_ends(diameter, width, length, center):
    outline = chamber_with_conduits(diameter, width, length, center)
    r, half_w, l_nm = diameter / 2 * 1e9, width / 2 * 1e9, length * 1e9
    cx, cy = center[0] * 1e9, center[1] * 1e9
    x_end = math.sqrt(r * r - half_w * half_w) + l_nm
    assert sorted(outline.port_names()) == ["input", "output"]
    ports = {name: np.asarray(seg.coords) for name, seg in outline.ports.items()}
    for name, sign in (("input", -1.0), ("output", +1.0)):
        xs, ys = ports[name][:, 0], ports[name][:, 1]
        np.testing.assert_allclose(xs, cx + sign * x_end, rtol=0, atol=1e-9)
        np.testing.assert_allclose(sorted(ys), [cy - half_w, cy + half_w], rtol=0, atol=1e-9)
    x0, y0, x1, y1 = outline._bounds_nm
    assert x0 == pytest.approx(cx - x_end, abs=1e-9) and x1 == pytest.approx(cx + x_end, abs=1e-9)
    assert y1 - y0 == pytest.approx(2 * r, abs=1e-6)
    # the ports are open: no wall at a conduit's end
    assert float(outline._wall_distance_nm(cx + x_end - 1e-3, cy)) == pytest.approx(
        half_w, abs=1e-6
    )


def test_chamber_area_is_disk_plus_conduits():
    outline = chamber_with_conduits(1024e-9, 100e-9, 50e-9, corner_radius=0.0)
    r, h, length = 512.0, 50.0, 50.0
    x_meet = math.sqrt(r * r - h * h)
    # each conduit box of height 2h from x_meet to x_meet + L, minus the circular cap of the
    # disk inside it: ∫_{-h}^{h} (√(R² − y²) − x_meet) dy
    cap = h * x_meet + r * r * math.asin(h / r) - 2 * h * x_meet
    exact = math.pi * r * r + 2 * (2 * h * length - cap)
    # the circle is a polygon within 0.05 nm: area low by at most ~2πR·0.05 nm²
    assert outline._area_nm2() == pytest.approx(exact, rel=2.5e-4)
    assert outline._area_nm2() < exact
    assert outline._area_nm2() == pytest.approx(math.pi * r * r + 2 * 2 * h * length, rel=1e-3)


def test_rounded_junctions_are_arcs_tangent_to_both_walls():
    """The fillet at a junction is an arc of radius ρ whose centre lies ρ beyond the conduit
    wall (y = h + ρ) and ρ beyond the chamber's circle (|c| = R + ρ): tangent to both."""
    sharp = chamber_with_conduits(1024e-9, 100e-9, 50e-9, corner_radius=0.0)
    rounded = chamber_with_conduits(1024e-9, 100e-9, 50e-9, corner_radius=20e-9)
    r, h, rho = 512.0, 50.0, 20.0
    pts = np.asarray(rounded.region.exterior.coords)
    new = pts[sharp.region.boundary.distance(shapely.points(pts)) > 1e-3]
    arc = new[(new[:, 0] > 0) & (new[:, 1] > 0)]  # the junction at (+x_meet, +h)
    assert len(arc) >= 5
    # algebraic circle fit: x² + y² + D x + E y + F = 0
    a_mat = np.column_stack([arc[:, 0], arc[:, 1], np.ones(len(arc))])
    d, e, f = np.linalg.lstsq(a_mat, -(arc[:, 0] ** 2 + arc[:, 1] ** 2), rcond=None)[0]
    centre = np.array([-d / 2, -e / 2])
    radius = math.sqrt(centre @ centre - f)
    assert radius == pytest.approx(rho, rel=0.01)
    assert centre[1] == pytest.approx(h + rho, abs=0.2)
    assert math.hypot(*centre) == pytest.approx(r + rho, abs=0.2)
    for name in rounded.ports:  # the ports do not move
        assert rounded.ports[name].equals(sharp.ports[name])


@pytest.mark.parametrize(
    "kwargs, field",
    [
        ({"conduit_width": 1024e-9}, "conduit_width"),
        ({"conduit_width": 2e-6}, "conduit_width"),
        ({"chamber_diameter": 0.0}, "chamber_diameter"),
        ({"chamber_diameter": -1e-6}, "chamber_diameter"),
        ({"conduit_width": 0.0}, "conduit_width"),
        ({"conduit_length": -50e-9}, "conduit_length"),
        ({"conduit_length": float("nan")}, "conduit_length"),
    ],
)
def test_bad_chamber_sizes_are_refused(kwargs, field):
    with pytest.raises(InputError) as err:
        chamber_with_conduits(**kwargs)
    assert err.value.field == field and field in str(err.value)


@pytest.mark.parametrize(
    "make, field",
    [
        (lambda: disk(diameter=0.0), "diameter"),
        (lambda: disk(diameter=-2e-7), "diameter"),
        (lambda: rectangle(-1e-7, 1e-7), "width"),
        (lambda: rectangle(1e-7, 0.0), "height"),
        (lambda: polygon([(0, 0), (1e-7, 0)]), "vertices"),
        (lambda: polygon([(0, 0), (1e-7, 1e-7), (1e-7, 0), (0, 1e-7)]), "geometry"),  # bow tie
    ],
)
def test_bad_shapes_are_refused(make, field):
    with pytest.raises(InputError) as err:
        make()
    assert err.value.field == field


def test_shapes_are_built_in_nanometres():
    d = disk(diameter=200e-9, center=(50e-9, 0.0))
    x0, y0, x1, y1 = d._bounds_nm
    assert (x0, x1) == pytest.approx((-50.0, 150.0), abs=1e-9)
    # an inscribed polygon within 0.05 nm of the circle: area low by < 2πR·0.05 nm²
    assert math.pi * 100.0**2 * (1 - 1e-3) < d._area_nm2() < math.pi * 100.0**2
    r = rectangle(300e-9, 100e-9, center=(0.0, 20e-9))
    assert r._bounds_nm == pytest.approx((-150.0, -30.0, 150.0, 70.0), abs=1e-9)
    p = polygon([(0, 0), (200e-9, 0), (0, 100e-9)])
    assert p._area_nm2() == pytest.approx(1e4, rel=1e-12)
    assert bool(p._contains_nm(10.0, 10.0)) and not bool(p._contains_nm(150.0, 90.0))


# -- unions and ports ---------------------------------------------------------------------------
def test_union_of_overlapping_shapes_keeps_ports():
    a = rectangle(200e-9, 100e-9).with_port("left", (-100e-9, -50e-9), (-100e-9, 50e-9))
    b = disk(diameter=160e-9, center=(120e-9, 0.0))
    u = union(a, b)
    assert u.port_names() == ["left"]
    assert (a | b).region.equals(u.region)
    assert u._area_nm2() > a._area_nm2()


def test_union_of_disjoint_shapes_is_refused():
    with pytest.raises(InputError) as err:
        union(disk(diameter=100e-9), disk(diameter=100e-9, center=(300e-9, 0.0)))
    assert err.value.field == "geometry"


def test_port_not_on_the_boundary_is_refused():
    rect = rectangle(200e-9, 100e-9)
    with pytest.raises(InputError) as err:
        rect.with_port("mid", (0.0, -50e-9), (0.0, 50e-9))  # across the interior
    assert err.value.field == "ports.mid"
    with pytest.raises(InputError) as err:
        rect.with_port("off", (-100e-9, -80e-9), (-100e-9, 80e-9))  # runs past the corners
    assert err.value.field == "ports.off"
    ok = rect.with_port("p", (100e-9, -20e-9), (100e-9, 20e-9))
    with pytest.raises(InputError) as err:
        ok.with_port("p", (-100e-9, -20e-9), (-100e-9, 20e-9))
    assert err.value.field == "port name"


def test_outline_record_round_trip():
    outline = chamber_with_conduits(400e-9, 60e-9, 40e-9)
    back = Outline.from_record(outline.describe())
    assert back.region.equals(outline.region)
    assert back.port_names() == outline.port_names()
    for name in outline.ports:
        assert back.ports[name].equals(outline.ports[name])


# -- wall field ---------------------------------------------------------------------------------
def _disk_points(radius, band, n, seed=0):
    rng = np.random.default_rng(seed)
    r = np.sqrt(rng.uniform((radius - band) ** 2, (radius - 0.2) ** 2, n))
    theta = rng.uniform(0, 2 * np.pi, n)
    return r * np.cos(theta), r * np.sin(theta), r, theta


@pytest.fixture(scope="module")
def disk_field():
    radius, band = 300.0, 60.0
    outline = disk(diameter=2 * radius * 1e-9)
    return outline, WallField.build(outline, SPACING_NM, band), radius, band


def test_disk_wall_normal_is_radial(disk_field):
    outline, field, radius, band = disk_field
    x, y, r, theta = _disk_points(radius, band, 4000)
    _, nx, ny = field.interpolate(x, y)
    # inward normal: −(cos θ, sin θ)
    ex, ey = -np.cos(theta), -np.sin(theta)
    angle = np.abs(np.arctan2(ex * ny - ey * nx, ex * nx + ey * ny))
    assert angle.max() < 0.03
    assert np.all(np.abs(np.hypot(nx, ny) - 1) < 1e-3)


def test_disk_wall_distance_is_close_to_the_circle(disk_field):
    # The disk is a polygon whose chords lie up to 0.05 nm inside the circle (geometry.py,
    # _CHORD_ERROR_NM); bilinear interpolation adds up to ~0.02 nm across the vertex ridges.
    outline, field, radius, band = disk_field
    x, y, r, _ = _disk_points(radius, band, 4000)
    d, _, _ = field.interpolate(x, y)
    assert np.max(np.abs(d - (radius - r))) < 0.075
    # against the exact distance to the polygon that is actually simulated
    assert np.max(np.abs(d - outline._wall_distance_nm(x, y))) < 0.03


def test_interpolation_error_report(disk_field):
    outline, field, radius, band = disk_field
    report = field.interpolation_error(outline, n_samples=2000)
    assert report["samples"] == 2000
    assert (
        0
        <= report["distance_error_median_nm"]
        <= report["distance_error_p99_nm"]
        <= report["distance_error_max_nm"]
        < 0.03
    )
    assert 0 <= report["normal_error_median_rad"] <= report["normal_error_max_rad"] < 0.05


def test_disk_field_sign_outside_and_far_nodes():
    radius, band = 150.0, 40.0
    field = WallField.build(disk(diameter=2 * radius * 1e-9), SPACING_NM, band)
    d, nx, ny = field.interpolate(np.array([radius + 5.0]), np.array([0.0]))
    assert d[0] == pytest.approx(-5.0, abs=0.1)  # beyond a wall: negative distance
    assert nx[0] == pytest.approx(-1.0, abs=1e-3)  # normal still points back inside
    # the centre is far beyond the band: an approximate distance, no normal
    d, nx, ny = field.interpolate(np.array([0.0]), np.array([0.0]))
    assert d[0] == pytest.approx(radius, abs=2 * SPACING_NM)
    assert nx[0] == 0.0 and ny[0] == 0.0


def test_rectangle_port_is_not_a_wall():
    width, height, band = 400.0, 200.0, 60.0
    # the whole right edge is an open port
    outline = rectangle(width * 1e-9, height * 1e-9).with_port(
        "exit", (200e-9, -100e-9), (200e-9, 100e-9)
    )
    field = WallField.build(outline, SPACING_NM, band)
    rng = np.random.default_rng(3)
    x = rng.uniform(-width / 2 + 0.5, width / 2 - 0.5, 20_000)
    y = rng.uniform(-height / 2 + 0.5, height / 2 - 0.5, 20_000)
    # exact: nearest of the left, bottom and top edges (the right edge is open)
    dists = np.stack([x + width / 2, height / 2 - y, y + height / 2])
    exact = dists.min(axis=0)
    np.testing.assert_allclose(outline._wall_distance_nm(x, y), exact, rtol=0, atol=1e-5)
    # grid: exact (bilinear of a linear function) where all four nodes share the nearest wall
    # (within a cell of the port the outside nodes measure to the corners instead)
    second = np.sort(dists, axis=0)[1]
    clean = (exact < band) & (second - exact > 3 * SPACING_NM) & (x < width / 2 - 2 * SPACING_NM)
    assert clean.sum() > 1000
    d, nx, ny = field.interpolate(x[clean], y[clean])
    np.testing.assert_allclose(d, exact[clean], rtol=0, atol=1e-6)
    # normals: inward normal of the nearest wall (points within one cell of a wall are checked
    # in test_normal_next_to_a_wall_on_grid_nodes_points_inward)
    normals = np.array([[1.0, 0.0], [0.0, -1.0], [0.0, 1.0]])[dists.argmin(axis=0)[clean]]
    away = exact[clean] > SPACING_NM
    np.testing.assert_allclose(np.column_stack([nx, ny])[away], normals[away], rtol=0, atol=1e-6)
    # next to the port the distance is to the top/bottom walls, not to the opening
    px = np.array([width / 2 - 1.0, width / 2 - 3.0, width / 2 - 1.0])
    py = np.array([10.0, 30.0, -80.0])  # off the medial axis y = 0
    d, nx, ny = field.interpolate(px, py)
    np.testing.assert_allclose(d, [90.0, 70.0, 20.0], rtol=0, atol=0.05)
    # pointing away from the nearest wall (tilted slightly by the nodes beyond the opening,
    # whose nearest wall point is a corner)
    np.testing.assert_allclose(nx, 0.0, atol=0.02)
    np.testing.assert_allclose(ny, [-1.0, -1.0, 1.0], atol=1e-3)
    # a closed rectangle has a wall there instead
    closed = WallField.build(rectangle(width * 1e-9, height * 1e-9), SPACING_NM, band)
    d, nx, _ = closed.interpolate(px[:1], py[:1])
    assert d[0] == pytest.approx(1.0, abs=1e-6) and nx[0] == pytest.approx(-1.0, abs=1e-6)


def test_normal_next_to_a_wall_on_grid_nodes_points_inward():
    field = WallField.build(rectangle(400e-9, 200e-9), SPACING_NM, 60.0)
    # within one cell of the left (x = -200) and bottom (y = -100) walls
    s = np.array([0.1, 0.5, 1.0, 2.0])
    _, nx, ny = field.interpolate(-200.0 + s, np.zeros_like(s))
    np.testing.assert_allclose(np.column_stack([nx, ny]), [[1.0, 0.0]] * len(s), atol=1e-6)
    _, nx, ny = field.interpolate(np.zeros_like(s), -100.0 + s)
    np.testing.assert_allclose(np.column_stack([nx, ny]), [[0.0, 1.0]] * len(s), atol=1e-6)


def test_normal_next_to_a_wall_between_grid_nodes_points_inward():
    # the right and top walls of this rectangle do not lie on grid nodes
    field = WallField.build(rectangle(400e-9, 200e-9), SPACING_NM, 60.0)
    s = np.array([0.1, 0.5, 1.0, 2.0])
    d, nx, ny = field.interpolate(200.0 - s, np.zeros_like(s))
    np.testing.assert_allclose(d, s, atol=1e-6)
    np.testing.assert_allclose(np.column_stack([nx, ny]), [[-1.0, 0.0]] * len(s), atol=1e-6)
    d, nx, ny = field.interpolate(np.zeros_like(s), 100.0 - s)
    np.testing.assert_allclose(d, s, atol=1e-6)
    np.testing.assert_allclose(np.column_stack([nx, ny]), [[0.0, -1.0]] * len(s), atol=1e-6)


def test_grid_bilinear_is_exact_for_linear_fields():
    grid = Grid(x0=-10.0, y0=5.0, spacing=0.5, nx=41, ny=21)
    gx, gy = grid.nodes()
    assert gx.shape == (21, 41)
    assert gx[0, 0] == -10.0 and gy[-1, 0] == 15.0 and gx[0, -1] == 10.0
    field = 3.0 * gx - 2.0 * gy + 1.0
    rng = np.random.default_rng(1)
    x, y = rng.uniform(-10, 10, 500), rng.uniform(5, 15, 500)
    np.testing.assert_allclose(grid.bilinear(field, x, y), 3 * x - 2 * y + 1, atol=1e-9)


# -- random placement ---------------------------------------------------------------------------
@pytest.mark.parametrize(
    "outline",
    [
        disk(diameter=600e-9),
        chamber_with_conduits(600e-9, 100e-9, 50e-9),
    ],
)
def test_random_positions_respect_separation_and_walls(outline):
    sep, wall = 1.5 * D_SK_NM, 1.0 * D_SK_NM
    pts = _random_positions_nm(outline, 25, sep, wall, np.random.default_rng(11))
    assert pts.shape == (25, 2)
    assert np.all(outline._contains_nm(pts[:, 0], pts[:, 1]))
    assert np.all(outline._wall_distance_nm(pts[:, 0], pts[:, 1]) >= wall)
    pair = np.hypot(pts[:, None, 0] - pts[None, :, 0], pts[:, None, 1] - pts[None, :, 1])
    assert pair[np.triu_indices(25, 1)].min() >= sep
    # reproducible with the same generator seed
    again = _random_positions_nm(outline, 25, sep, wall, np.random.default_rng(11))
    np.testing.assert_array_equal(pts, again)


def test_random_positions_that_do_not_fit_are_refused():
    with pytest.raises(InputError) as err:
        _random_positions_nm(
            disk(diameter=200e-9), 30, 60.0, 10.0, np.random.default_rng(0), max_tries=3000
        )
    assert err.value.field == "skyrmions.count"


# -- the SI queries -------------------------------------------------------------------------------
def test_si_queries_agree_with_the_nanometre_ones():
    outline = chamber_with_conduits(chamber_diameter=600e-9)
    rng = np.random.default_rng(3)
    x0, y0, x1, y1 = outline._bounds_nm
    x = rng.uniform(x0, x1, 200)
    y = rng.uniform(y0, y1, 200)
    np.testing.assert_array_equal(outline.contains(x * 1e-9, y * 1e-9), outline._contains_nm(x, y))
    np.testing.assert_allclose(
        outline.wall_distance(x * 1e-9, y * 1e-9) * 1e9,
        outline._wall_distance_nm(x, y),
        rtol=1e-12,
    )
    assert outline.area() * 1e18 == pytest.approx(outline._area_nm2(), rel=1e-15)
    assert np.array(outline.bounds) * 1e9 == pytest.approx(outline._bounds_nm, rel=1e-15)


def test_a_disk_is_given_by_its_diameter():
    d = disk(diameter=200e-9, center=(50e-9, 0.0))
    x0, y0, x1, y1 = d.bounds
    assert (x0, x1) == pytest.approx((-50e-9, 150e-9), rel=1e-9)
    assert math.pi * (100e-9) ** 2 * (1 - 1e-3) < d.area() < math.pi * (100e-9) ** 2
    with pytest.raises(TypeError):
        disk(200e-9)  # a bare number could be a radius: the keyword is required


def test_si_random_positions_are_the_nanometre_ones_in_metres():
    outline = chamber_with_conduits(chamber_diameter=600e-9)
    si = random_positions(outline, 20, 45e-9, 30e-9, np.random.default_rng(8))
    nm = _random_positions_nm(outline, 20, 45.0, 30.0, np.random.default_rng(8))
    np.testing.assert_allclose(si * 1e9, nm, rtol=1e-12)
    assert np.all(outline.contains(si[:, 0], si[:, 1]))
    assert np.all(outline.wall_distance(si[:, 0], si[:, 1]) >= 30e-9 * (1 - 1e-12))
    gaps = np.hypot(*(si[:, None, :] - si[None, :, :]).transpose(2, 0, 1))
    assert gaps[np.triu_indices(20, 1)].min() >= 45e-9 * (1 - 1e-12)


def test_the_former_nanometre_names_warn_and_still_answer():
    outline = disk(diameter=200e-9)
    with pytest.warns(DeprecationWarning, match="Outline.contains"):
        assert bool(outline.contains_nm(0.0, 0.0))
    with pytest.warns(DeprecationWarning, match="Outline.area"):
        assert outline.area_nm2() == outline._area_nm2()
    with pytest.warns(DeprecationWarning, match="Outline.bounds"):
        assert outline.bounds_nm == outline._bounds_nm
    with pytest.warns(DeprecationWarning, match="Outline.wall_distance"):
        assert outline.wall_distance_nm(0.0, 0.0) == pytest.approx(100.0, rel=1e-3)


@pytest.mark.parametrize(
    "make, field",
    [
        (lambda: chamber_with_conduits(800), "chamber_diameter"),
        (lambda: disk(diameter=800), "diameter"),
        (lambda: disk(diameter=1e-15), "diameter"),
    ],
)
def test_a_length_in_another_unit_is_named_as_from_the_command_line(make, field):
    """800 for 800 nm gets the command line's words, not a port's 'segment' error."""
    with pytest.raises(InputError) as err:
        make()
    assert err.value.field == field
    assert "lengths are in metres: did you mean" in str(err.value)
