"""Charge, dissipation, centres and radii on analytic profiles with known answers."""

import math

import numpy as np
import pytest

from skygas.micromag import (
    detect_skyrmions,
    dissipation,
    field_from_array,
    synthetic,
    topological_charge,
)
from skygas.micromag.workflow import thiele_coefficients
from skygas.physics.materials import derive_thiele, preset

CELL = 1e-9  # m, as the conftest's field
RADIUS = 10e-9  # m
WALL_WIDTH = 3e-9  # m


def test_charge_per_skyrmion_and_total(two_skyrmions):
    snap = detect_skyrmions(two_skyrmions)
    assert len(snap.skyrmions) == 2
    for sk in snap.skyrmions:
        assert sk.charge == pytest.approx(-1.0, abs=1e-3)
    assert snap.total_charge == pytest.approx(-2.0, abs=1e-3)
    assert topological_charge(two_skyrmions) == pytest.approx(snap.total_charge, abs=1e-12)


@pytest.mark.parametrize(
    "polarity, helicity, expected",
    [
        (1, 0.0, -1.0),  # Néel, core down in an up film
        (1, math.pi / 2, -1.0),  # Bloch: the helicity does not change Q
        (-1, 0.0, 1.0),  # core up in a down film
    ],
)
def test_sign_convention(polarity, helicity, expected):
    field = synthetic.skyrmion_field(
        (80, 80),
        CELL,
        [(40.2e-9, 39.7e-9)],
        RADIUS,
        WALL_WIDTH,
        polarity=polarity,
        helicity=helicity,
    )
    (sk,) = detect_skyrmions(field).skyrmions
    assert sk.charge == pytest.approx(expected, abs=1e-3)


def test_lattice_charge_is_an_integer_even_when_coarse():
    # Berg–Lüscher: exact integer for a field uniform on the border, whatever the resolution
    # (here a 14 nm-radius skyrmion on 4 nm cells); the tails are cut by a far border.
    field = synthetic.skyrmion_field((60, 60), 4e-9, [(121e-9, 118.5e-9)], 14e-9, 3e-9)
    assert topological_charge(field) == pytest.approx(-1.0, abs=1e-9)


def test_dissipation_matches_the_ansatz_integral(two_skyrmions):
    expected = synthetic.ansatz_dissipation(RADIUS, WALL_WIDTH)
    # Thin-wall limit 2π(R/Δ + Δ/R) as a sanity check of the quadrature itself (≈ 5 % here).
    assert expected == pytest.approx(
        2 * math.pi * (RADIUS / WALL_WIDTH + WALL_WIDTH / RADIUS), rel=0.1
    )
    for sk in detect_skyrmions(two_skyrmions).skyrmions:
        assert sk.dissipation == pytest.approx(expected, rel=0.02)


def test_dissipation_of_a_uniform_rotation_is_exact():
    # n = (cos kx, sin kx, 0): 𝒟 = ½ k² × (area spanned by the x-links), exactly on the lattice.
    nx, ny, dx = 40, 7, 2e-9
    k = 0.3 / dx
    x = (np.arange(nx) + 0.5) * dx
    m = np.zeros((ny, nx, 3))
    m[..., 0], m[..., 1] = np.cos(k * x), np.sin(k * x)
    field = field_from_array(m, dx)
    assert dissipation(field) == pytest.approx(0.5 * k**2 * (nx - 1) * dx * ny * dx, rel=1e-12)


def test_centres_within_five_hundredths_of_a_cell(two_skyrmions, profile):
    snap = detect_skyrmions(two_skyrmions)
    found = sorted((s.x, s.y) for s in snap.skyrmions)
    for (x, y), (x0, y0) in zip(found, sorted(profile.centres), strict=True):
        assert abs(x - x0) < 0.05 * CELL and abs(y - y0) < 0.05 * CELL


def test_radius_within_one_percent(two_skyrmions):
    for sk in detect_skyrmions(two_skyrmions).skyrmions:
        assert sk.radius == pytest.approx(RADIUS, rel=0.01)
        assert sk.circularity == pytest.approx(1.0, abs=0.01)


def test_per_region_values_sum_to_the_total(two_skyrmions):
    snap = detect_skyrmions(two_skyrmions)
    labels = np.where(snap.labels > 0, snap.labels, 3)  # the rest of the film as region 3
    charges = topological_charge(two_skyrmions, labels)
    assert charges[2] == pytest.approx(0.0, abs=1e-4)  # neighbourhoods hold all the charge
    assert charges.sum() == pytest.approx(topological_charge(two_skyrmions), abs=1e-12)
    assert dissipation(two_skyrmions, labels).sum() == pytest.approx(
        dissipation(two_skyrmions), rel=1e-12
    )


def test_empty_cells_outside_a_disk_are_left_out():
    ny = nx = 90
    yy, xx = np.mgrid[0:ny, 0:nx] + 0.5
    disk = np.hypot(xx - 45, yy - 45) < 42
    field = synthetic.skyrmion_field(
        (ny, nx), CELL, [(45.3e-9, 44.6e-9)], RADIUS, WALL_WIDTH, mask=disk
    )
    (sk,) = detect_skyrmions(field).skyrmions
    assert sk.charge == pytest.approx(-1.0, abs=1e-3)
    assert sk.dissipation == pytest.approx(
        synthetic.ansatz_dissipation(RADIUS, WALL_WIDTH), rel=0.02
    )


def test_no_skyrmion_in_a_uniform_film():
    m = np.zeros((20, 20, 3))
    m[..., 2] = 1.0
    snap = detect_skyrmions(field_from_array(m, CELL))
    assert snap.skyrmions == () and snap.total_charge == 0.0


def test_gyrocoupling_convention_matches_materials():
    # G = −4πQk and α𝒟k, as skygas.physics.materials.derive_thiele computes them for Q = −1.
    material = preset("S2")
    derived = derive_thiele(material, 2e-9, dissipation=25.0)
    measured = thiele_coefficients(-1.0, 25.0, material, 2e-9)
    assert measured["gyrocoupling"] == pytest.approx(derived.gyrocoupling, rel=1e-12)
    assert measured["gyrocoupling"] > 0
    assert measured["friction"] == pytest.approx(derived.friction, rel=1e-12)
