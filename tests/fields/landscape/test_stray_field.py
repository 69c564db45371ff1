"""The edge stray field of a perpendicular film and a skyrmion's energy in it
(skygas.fields.landscape.stray_field; docs/physics.md §2), against closed forms."""

import math

import numpy as np
import pytest
from scipy import integrate

from skygas.core.errors import InputError
from skygas.fields.landscape.stray_field import (
    MU_0,
    cell_kernel,
    edge_field,
    stray_field_energy,
)

T = 2e-9  # film thickness [m]
H = T / 2
MS = 1.0e6  # [A/m]


def solid_angle(x0, x1, y0, y1, x, y, h=H):
    """∫∫_[x0,x1]×[y0,y1] h/((x'−x)² + (y'−y)² + h²)^{3/2} dA' in closed form (corner sum)."""

    def f(a, b):
        return np.arctan(a * b / (h * np.sqrt(a * a + b * b + h * h)))

    return f(x1 - x, y1 - y) - f(x0 - x, y1 - y) - f(x1 - x, y0 - y) + f(x0 - x, y0 - y)


@pytest.mark.parametrize("offset", [(0, 0), (1, 0), (2, -3), (7, 5), (-40, 13)])
@pytest.mark.parametrize("height", [0.2, 0.5, 2.0])
def test_cell_kernel_is_the_integral_over_the_cell(offset, height):
    ox, oy = offset
    exact, _ = integrate.dblquad(
        lambda y, x: height / (x * x + y * y + height**2) ** 1.5,
        ox - 0.5,
        ox + 0.5,
        oy - 0.5,
        oy + 0.5,
        epsabs=0,
        epsrel=1e-12,
    )
    assert float(cell_kernel(ox, oy, height)) == pytest.approx(exact, rel=1e-9, abs=0)


def test_rectangular_film_field_is_exact_at_every_node():
    """A rectangle along grid lines is the union of its cells: H_dev = M_s (1 − Ω/2π) with Ω
    the rectangle's corner sum, to rounding (1e-12 M_s)."""
    s = 1.5e-9
    ny, nx = 60, 90
    inside = np.zeros((ny, nx), bool)
    inside[10:50, 20:75] = True
    field = edge_field(inside, s, T, MS)
    x = np.arange(nx) * s
    y = np.arange(ny)[:, None] * s
    omega = solid_angle(19.5 * s, 74.5 * s, 9.5 * s, 49.5 * s, x[None, :], y)
    np.testing.assert_allclose(field, MS * (1 - omega / (2 * np.pi)), rtol=0, atol=1e-12 * MS)
    # the mean over 3 × 3 points of each cell: the mean of the closed form at those points
    points = (np.arange(3) + 0.5) / 3 - 0.5
    mean = np.mean(
        [
            solid_angle(19.5 * s, 74.5 * s, 9.5 * s, 49.5 * s, x[None, :] + px * s, y + py * s)
            for px in points
            for py in points
        ],
        axis=0,
    )
    np.testing.assert_allclose(
        edge_field(inside, s, T, MS, subsamples=3),
        MS * (1 - mean / (2 * np.pi)),
        rtol=0,
        atol=1e-12 * MS,
    )


def test_half_plane_field_is_the_straight_edge_formula():
    """Near one edge of a 24 µm square film, far from the others: H_dev = (M_s/π) atan(t/2x)
    within 1 % for x from 5t to 30t (the other three edges add < 0.7 % there). Cells of 12 t
    put the nodes at x = 6t, 18t, 30t from the edge; cells along the edge are exact."""
    s = 12 * T
    n = 1000
    inside = np.ones((n, n), bool)
    field = edge_field(inside, s, T, MS)
    x = (np.arange(3) + 0.5) * s
    expected = MS / np.pi * np.arctan(T / (2 * x))
    np.testing.assert_allclose(field[n // 2, :3], expected, rtol=1e-2)


def test_disk_centre_field_is_the_two_sheet_disk_formula():
    """At the centre of a disk of radius a: H_dev = M_s h/√(a² + h²), h = t/2 (within 5e-4,
    the disk drawn with 1 nm cells)."""
    a, s = 200e-9, 1e-9
    n = int(a / s) + 3
    grid = np.arange(-n, n + 1) * s
    inside = grid[None, :] ** 2 + grid[:, None] ** 2 <= a * a
    field = edge_field(inside, s, T, MS)
    assert field[n, n] == pytest.approx(MS * H / math.sqrt(a * a + H * H), rel=5e-4, abs=0)
    # and the field grows towards the rim along every axis
    assert np.all(np.diff(field[n, n : n + 190]) > 0)
    np.testing.assert_allclose(field[n, n : n + 190], field[n : n + 190, n], rtol=1e-12)


def test_cell_averages_converge_to_the_node_values_far_from_edges():
    inside = np.ones((40, 40), bool)
    node = edge_field(inside, 2e-9, T, MS)
    mean = edge_field(inside, 2e-9, T, MS, subsamples=4)
    # the mean over a cell exceeds the centre value at the rim (H_dev ∝ atan(h/x) is convex)
    assert mean[20, 0] > node[20, 0]
    np.testing.assert_allclose(mean[15:25, 15:25], node[15:25, 15:25], rtol=2e-3)


def test_stray_field_energy_against_direct_quadrature():
    """U = μ₀ M_s t ∫_film w(|r' − r|) H_dev(r') dA' of a rectangle: the FFT result on 2 nm
    cells against a direct sum on 0.25 nm sub-cells with the exact rectangle field, within
    0.3 % at 5–81 nm from the nearest edge (the skyrmion's wall across the edge or not)."""
    s = 2e-9
    ny, nx = 80, 120
    inside = np.zeros((ny, nx), bool)
    x0, x1, y0, y1 = 9.5 * s, 109.5 * s, 9.5 * s, 69.5 * s  # the film's corners
    inside[10:70, 10:110] = True
    radius = np.linspace(0.0, 60e-9, 61)
    deficit = np.interp(radius, [0.0, 15e-9, 25e-9, 60e-9], [2.0, 1.8, 0.1, 0.0])
    energy = stray_field_energy(inside, s, T, MS, radius, deficit)
    fine = 0.25e-9
    for i in (12, 15, 20, 30, 50):  # node x = i·s, 5 to 81 nm from the left edge
        j = 40
        cx, cy = i * s, j * s
        xs = np.arange(max(x0, cx - 60e-9) + fine / 2, min(x1, cx + 60e-9), fine)
        ys = np.arange(max(y0, cy - 60e-9) + fine / 2, min(y1, cy + 60e-9), fine)
        px, py = np.meshgrid(xs, ys)
        w = np.interp(np.hypot(px - cx, py - cy), radius, deficit, right=0.0)
        field = MS * (1 - solid_angle(x0, x1, y0, y1, px, py) / (2 * np.pi))
        reference = MU_0 * MS * T * np.sum(w * field) * fine * fine
        assert energy[j, i] == pytest.approx(reference, rel=3e-3, abs=0)


@pytest.mark.parametrize(
    "call, field",
    [
        (lambda: edge_field(np.ones(5, bool), 1e-9, T, MS), "inside"),
        (lambda: edge_field(np.full((4, 4), 2.0), 1e-9, T, MS), "inside"),
        (lambda: edge_field(np.ones((4, 4)), 1e-9, -T, MS), "thickness"),
        (lambda: edge_field(np.ones((4, 4)), float("nan"), T, MS), "spacing"),
        (lambda: edge_field(np.ones((4, 4)), 1e-9, T, MS, subsamples=0), "subsamples"),
        (
            lambda: stray_field_energy(np.ones((4, 4)), 1e-9, T, MS, [1e-9, 2e-9], [1.0, 0.0]),
            "profile_radius",
        ),
        (
            lambda: stray_field_energy(np.ones((4, 4)), 1e-9, T, MS, [0.0, 2e-9], [1.0]),
            "profile_deficit",
        ),
    ],
)
def test_bad_arguments_are_refused_in_one_line(call, field):
    with pytest.raises(InputError) as err:
        call()
    assert err.value.field == field and "\n" not in str(err.value)
