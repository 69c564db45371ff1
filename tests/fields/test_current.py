"""Current flow (skygas.fields.current): conservation, exact solutions, scaling, insulating
walls."""

import json
import math

import numpy as np
import pytest
from shapely.geometry import LineString, Polygon

from skygas.core.errors import InputError
from skygas.fields.current import DEFAULT_CONDUCTOR_THICKNESS, DEFAULT_RESISTIVITY, solve_current
from skygas.fields.wall_field import Grid
from skygas.figures.plotting import plot_current
from skygas.physics.geometry import Outline, chamber_with_conduits, rectangle

J = 1.7e11  # A/m², a current density of the paper's sweep
CHAMBER_DIAMETER = 1024e-9
CONDUIT_WIDTH = 100e-9
COARSE = 8e-9  # cell size for the chamber tests (~1.3e4 cells)


@pytest.fixture(scope="module")
def chamber():
    # sharp junctions: the paper's geometry, on which the accuracy figures are stated
    return chamber_with_conduits(CHAMBER_DIAMETER, CONDUIT_WIDTH, 50e-9, corner_radius=0.0)


@pytest.fixture(scope="module")
def chamber_solution(chamber):
    return solve_current(chamber, J, cell_size=COARSE)


def _port_x(outline, name):
    return outline.ports[name].coords[0][0] * 1e-9  # metres


def strip(length=412e-9, width=100e-9, vertical=False):
    """A straight strip with ports "a" and "b" on its short ends."""
    if vertical:
        out = rectangle(width, length)
        return out.with_port("a", (-width / 2, -length / 2), (width / 2, -length / 2)).with_port(
            "b", (-width / 2, length / 2), (width / 2, length / 2)
        )
    out = rectangle(length, width)
    return out.with_port("a", (-length / 2, -width / 2), (-length / 2, width / 2)).with_port(
        "b", (length / 2, -width / 2), (length / 2, width / 2)
    )


# -- conservation ----------------------------------------------------------------------------
def test_net_current_through_cross_sections_equals_total(chamber, chamber_solution):
    s = chamber_solution
    x_in, x_out = _port_x(chamber, "input"), _port_x(chamber, "output")
    half = 0.6 * CONDUIT_WIDTH
    cuts = [
        ((x_in + 5e-9, -half), (x_in + 5e-9, half)),  # input conduit, near the port
        ((x_in + 30e-9, -half), (x_in + 30e-9, half)),  # input conduit, inside
        ((0.0, -600e-9), (0.0, 600e-9)),  # chamber centre
        ((-200e-9, -600e-9), (-200e-9, 600e-9)),  # chamber, off centre
        ((300e-9, -600e-9), (300e-9, 600e-9)),
        ((x_out - 30e-9, -half), (x_out - 30e-9, half)),  # output conduit
        ((-100e-9, 700e-9), (100e-9, -700e-9)),
    ]  # an oblique cut
    for start, end in cuts:
        # upward-pointing cuts count +x current; the oblique one points downwards
        sign = 1.0 if end[1] > start[1] else -1.0
        flux = sign * s.flux_through(start, end)
        assert flux == pytest.approx(s.total_current, rel=1e-2), (start, end)
    # a cut along the symmetry axis carries no net current
    assert abs(s.flux_through((-400e-9, 0.0), (400e-9, 0.0))) < 1e-2 * s.total_current


def test_discrete_current_is_conserved(chamber_solution):
    assert chamber_solution.conservation_error < 1e-9


def test_mean_density_across_conduits_is_J(chamber, chamber_solution):
    s = chamber_solution
    assert s.mean_current_density("input") == pytest.approx(J, rel=1e-6)
    assert s.mean_current_density("output") == pytest.approx(J, rel=1e-2)
    # the same from the sampled field, integrated across each conduit
    x_in, x_out = _port_x(chamber, "input"), _port_x(chamber, "output")
    half = CONDUIT_WIDTH / 2
    area = CONDUIT_WIDTH * s.conductor_thickness
    mean_in = s.flux_through((x_in + 20e-9, -half), (x_in + 20e-9, half)) / area
    mean_out = s.flux_through((x_out - 20e-9, -half), (x_out - 20e-9, half)) / area
    assert mean_in == pytest.approx(J, rel=1e-6)
    assert mean_out == pytest.approx(J, rel=1e-2)
    assert s.total_current == pytest.approx(J * CONDUIT_WIDTH * s.conductor_thickness, rel=1e-12)


# -- exact solutions -------------------------------------------------------------------------
@pytest.mark.parametrize("vertical", [False, True])
@pytest.mark.parametrize("cell_size", [10e-9, 7e-9])
def test_straight_strip_is_uniform_with_exact_resistance(vertical, cell_size):
    length, width = 412e-9, 100e-9
    s = solve_current(strip(length, width, vertical), J, source="a", sink="b", cell_size=cell_size)
    # nodes inside and a little outside the strip
    lo = -(length / 2 + 20e-9) * 1e9
    grid = Grid(lo, lo, 3.7, int(-2 * lo / 3.7) + 1, int(-2 * lo / 3.7) + 1)
    jx, jy = s.sample(grid)
    along, across = (jy, jx) if vertical else (jx, jy)
    np.testing.assert_allclose(along, J, rtol=1e-6)
    np.testing.assert_allclose(across, 0.0, atol=1e-6 * J)
    rho, t = s.resistivity, s.conductor_thickness
    assert s.resistance == pytest.approx(rho * length / (width * t), rel=1e-2)
    assert s.voltage == pytest.approx(J * rho * length, rel=1e-2)


def test_annular_sector_radial_flow():
    """Current between two concentric arcs: j = J r₁/r radially, R = ρ ln(r₂/r₁)/(θ t)."""
    r1, r2, theta = 100e-9, 400e-9, math.pi / 2
    a = np.linspace(0, theta, 200)
    inner = np.c_[np.cos(a), np.sin(a)] * r1 * 1e9
    outer = np.c_[np.cos(a), np.sin(a)] * r2 * 1e9
    outline = Outline(
        Polygon(np.vstack([inner, outer[::-1]])),
        {"inner": LineString(inner), "outer": LineString(outer)},
    )
    s = solve_current(outline, J, source="inner", sink="outer", cell_size=10e-9)
    expected = s.resistivity * math.log(r2 / r1) / (theta * s.conductor_thickness)
    assert s.resistance == pytest.approx(expected, rel=5e-3)
    b = np.linspace(0.2, theta - 0.2, 30)
    for r in (150e-9, 250e-9, 350e-9):
        jx, jy = s.current_density_at(r * np.cos(b), r * np.sin(b))
        np.testing.assert_allclose(jx * np.cos(b) + jy * np.sin(b), J * r1 / r, rtol=5e-3)
        np.testing.assert_allclose(-jx * np.sin(b) + jy * np.cos(b), 0.0, atol=5e-3 * J)


# -- scaling, direction ----------------------------------------------------------------------
def test_linear_scaling(chamber, chamber_solution):
    s1 = chamber_solution
    s2 = solve_current(chamber, 2 * J, cell_size=COARSE)
    grid = Grid(-600.0, -300.0, 10.0, 121, 61)
    (jx1, jy1), (jx2, jy2) = s1.sample(grid), s2.sample(grid)
    np.testing.assert_allclose(jx2, 2 * jx1, rtol=1e-9, atol=1e-9 * J)
    np.testing.assert_allclose(jy2, 2 * jy1, rtol=1e-9, atol=1e-9 * J)
    assert s2.resistance == pytest.approx(s1.resistance, rel=1e-12)
    assert s2.total_current == pytest.approx(2 * s1.total_current, rel=1e-12)
    assert s2.voltage == pytest.approx(2 * s1.voltage, rel=1e-12)
    assert s2.power == pytest.approx(4 * s1.power, rel=1e-12)
    assert s1.power == pytest.approx(s1.total_current**2 * s1.resistance, rel=1e-12)
    assert s1.power == pytest.approx(s1.voltage * s1.total_current, rel=1e-12)


def test_reversed_current_and_swapped_ports(chamber, chamber_solution):
    grid = Grid(-600.0, -300.0, 10.0, 121, 61)
    jx, _ = chamber_solution.sample(grid)
    back = solve_current(chamber, -J, cell_size=COARSE)
    swapped = solve_current(chamber, J, source="output", sink="input", cell_size=COARSE)
    np.testing.assert_allclose(back.sample(grid)[0], -jx, rtol=1e-9, atol=1e-9 * J)
    assert back.power == pytest.approx(chamber_solution.power, rel=1e-12)
    # swapping the electrodes of the mirror-symmetric chamber gives the mirror image of the flow
    # (the grid, aligned with the source port, is mirrored too; the sample grid is symmetric).
    # Next to walls the nearest-cell extension breaks ties by scan order: compare ≥ 2 cells in.
    gx, gy = grid.nodes()
    away = chamber._contains_nm(gx, gy) & (chamber._wall_distance_nm(gx, gy) > 2 * COARSE * 1e9)
    sx, sy = swapped.sample(grid)
    _, jy = chamber_solution.sample(grid)
    np.testing.assert_allclose(sx[away], -jx[:, ::-1][away], rtol=1e-6, atol=1e-6 * J)
    np.testing.assert_allclose(sy[away], jy[:, ::-1][away], rtol=1e-6, atol=1e-6 * J)
    assert swapped.resistance == pytest.approx(chamber_solution.resistance, rel=1e-2)


def test_resistance_scales_with_material_not_field(chamber, chamber_solution):
    thick = solve_current(chamber, J, cell_size=COARSE, conductor_thickness=10e-9, resistivity=4e-7)
    s = chamber_solution
    assert thick.resistance == pytest.approx(s.resistance * (4e-7 / 2e-7) / 2, rel=1e-12)
    assert thick.total_current == pytest.approx(2 * s.total_current, rel=1e-12)
    np.testing.assert_allclose(
        thick.current_density_at(0.0, 0.0), s.current_density_at(0.0, 0.0), rtol=1e-12
    )


# -- walls -----------------------------------------------------------------------------------
def test_walls_are_insulating(chamber_solution):
    s = chamber_solution
    radius = CHAMBER_DIAMETER / 2
    angle = np.linspace(0.3, math.pi - 0.3, 300)  # away from the conduits
    angle = np.concatenate([angle, -angle])
    r = radius - 2 * COARSE
    jx, jy = s.current_density_at(r * np.cos(angle), r * np.sin(angle))
    normal = jx * np.cos(angle) + jy * np.sin(angle)
    tangential = -jx * np.sin(angle) + jy * np.cos(angle)
    assert np.max(np.abs(normal)) < 0.06 * J
    assert np.mean(np.abs(normal)) < 0.15 * np.mean(np.abs(tangential))
    # along a straight conduit wall the normal component vanishes to round-off
    x = np.linspace(-555e-9, -540e-9, 20)
    _, jy_wall = s.current_density_at(x, np.full_like(x, CONDUIT_WIDTH / 2 - 1e-9))
    np.testing.assert_allclose(jy_wall, 0.0, atol=1e-2 * J)


def test_sample_extends_outside_and_feeds_drift(chamber_solution):
    s = chamber_solution
    grid = Grid(-620.0, -560.0, 4.0, 311, 281)
    jx, jy = s.sample(grid)
    assert jx.shape == jy.shape == (281, 311)
    assert np.all(np.isfinite(jx)) and np.all(np.isfinite(jy))
    # just outside the conduit wall the field continues the inside value
    inside = s.current_density_at(-540e-9, 45e-9)
    outside = s.current_density_at(-540e-9, 55e-9)
    np.testing.assert_allclose(outside, inside, rtol=0.05, atol=1e-3 * J)
    vx, vy = s.drift_velocity(grid, 1e-10)
    np.testing.assert_allclose(vx, 1e-10 * jx)
    np.testing.assert_allclose(vy, 1e-10 * jy)


# -- derived quantities, record, figure ------------------------------------------------------
def test_energy_per_bit_and_record(chamber_solution):
    s = chamber_solution
    assert s.energy_per_bit(5e-9) == pytest.approx(s.power * 5e-9, rel=1e-12)
    record = json.loads(json.dumps(s.record()))
    assert record["conductor_thickness_m"] == DEFAULT_CONDUCTOR_THICKNESS
    assert record["resistivity_ohm_m"] == DEFAULT_RESISTIVITY
    assert record["power_W"] == pytest.approx(s.power)
    assert record["port_mean_current_density_A_per_m2"]["input"] == pytest.approx(J)
    with pytest.raises(InputError):
        s.energy_per_bit(0.0)


def test_plot_current_writes_png(tmp_path, chamber, chamber_solution):
    path = plot_current(chamber_solution, chamber, tmp_path / "current.png")
    assert path.exists() and path.read_bytes()[:4] == b"\x89PNG"


# -- bad input -------------------------------------------------------------------------------
@pytest.mark.parametrize(
    "kwargs, field",
    [
        ({"conductor_thickness": 0.0}, "conductor_thickness"),
        ({"conductor_thickness": -5e-9}, "conductor_thickness"),
        ({"resistivity": 0.0}, "resistivity"),
        ({"resistivity": float("nan")}, "resistivity"),
        ({"cell_size": -1e-9}, "cell_size"),
        ({"cell_size": 1e-12}, "cell_size"),  # far too many cells: refused before allocating
        ({"source": "inlet"}, "source"),
        ({"sink": ["output", "drain"]}, "sink"),
        ({"source": "input", "sink": "input"}, "sink"),
        ({"source": []}, "source"),
    ],
)
def test_bad_input_raises(chamber, kwargs, field):
    with pytest.raises(InputError) as info:
        solve_current(chamber, J, **kwargs)
    assert info.value.field == field


@pytest.mark.parametrize("value", [float("inf"), float("nan"), "1e11", None])
def test_bad_current_density(chamber, value):
    with pytest.raises(InputError) as info:
        solve_current(chamber, value, cell_size=COARSE)
    assert info.value.field == "current_density"


def test_outline_without_ports_raises():
    with pytest.raises(InputError) as info:
        solve_current(rectangle(400e-9, 100e-9), J)
    assert info.value.field == "source"


def test_electrodes_cut_apart_by_coarse_cells_raise():
    """A 3 nm neck between two pads is not resolved by 10 nm cells: refused, not a singular
    matrix or a silent zero current."""
    pads = (
        rectangle(195e-9, 100e-9, center=(-102.5e-9, 0.0))
        | rectangle(12e-9, 3e-9)
        | rectangle(195e-9, 100e-9, center=(102.5e-9, 0.0))
    )
    device = pads.with_port("a", (-200e-9, -50e-9), (-200e-9, 50e-9)).with_port(
        "b", (200e-9, -50e-9), (200e-9, 50e-9)
    )
    with pytest.raises(InputError) as info:
        solve_current(device, J, source="a", sink="b", cell_size=10e-9)
    assert info.value.field == "cell_size"
    fine = solve_current(device, J, source="a", sink="b", cell_size=1e-9)
    # the 10 nm free length of the 3 nm neck alone is a lower bound on the resistance
    assert fine.resistance > fine.resistivity * 10e-9 / (3e-9 * fine.conductor_thickness)


def test_rounded_default_chamber_conserves_current():
    """The reshuffler's default chamber has rounded junctions; the current still crosses every
    section of it unchanged."""
    rounded = chamber_with_conduits(CHAMBER_DIAMETER, CONDUIT_WIDTH, 50e-9)
    s = solve_current(rounded, J, cell_size=COARSE)
    for x in (-530e-9, 0.0, 300e-9, 530e-9):
        flux = s.flux_through((x, -600e-9), (x, 600e-9))
        assert abs(abs(flux) - s.total_current) < 0.01 * s.total_current
