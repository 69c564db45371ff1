"""The isolated skyrmion's measurements on analytic profiles with known answers: G from the
measured Q, the dissipation tensor against quadrature, the thin-wall estimate's normalisation,
the wall-width fit. NumPy only: no solver."""

from __future__ import annotations

import math

import numpy as np
import pytest

from skygas.calibration.material import load_micromagnetic_material
from skygas.calibration.profile import (
    dissipation_tensor,
    fit_wall_width,
    measure_isolated,
    radial_profile,
    thin_wall_dissipation,
)
from skygas.calibration.solver import Film, skyrmion_texture
from skygas.micromag.synthetic import ansatz_dissipation


def _ansatz(radius=20e-9, width=5e-9, cell=0.5e-9, side=200e-9):
    n = int(round(side / cell)) | 1
    film = Film(n, n, cell)
    centre = (0.5 * n * cell, 0.5 * n * cell)
    return film, centre, skyrmion_texture(film, [centre], radius, width)


def test_g_is_minus_four_pi_q_k_with_the_measured_charge():
    film, _, m = _ansatz(cell=1e-9)
    material = load_micromagnetic_material("S2", cell_size=1e-9)
    iso = measure_isolated(m, film, material, energy=1e-19)
    k = material.saturation_magnetization * material.film_thickness / material.gyromagnetic_ratio
    assert iso.k == k
    assert iso.gyrocoupling == -4.0 * math.pi * iso.charge * k  # exactly the formula
    assert iso.charge == pytest.approx(-1.0, abs=1e-3)  # the lattice charge of the ansatz
    assert iso.gyrocoupling > 0  # docs/physics.md §1: G > 0 for the paper's skyrmion


@pytest.mark.parametrize("radius, width", [(20e-9, 5e-9), (12e-9, 4e-9), (30e-9, 3e-9)])
def test_dissipation_of_the_ansatz_matches_quadrature(radius, width):
    """𝒟 = ½∫(∂ₓm·∂ₓm + ∂ᵧm·∂ᵧm) dA of the 360° wall ansatz, against π∫(θ'² + sin²θ/r²) r dr
    by adaptive quadrature: within 0.5 % with Δ = 6–10 cells; the tensor is isotropic."""
    film, _, m = _ansatz(radius, width)
    tensor = dissipation_tensor(m, film.cell_size)
    expected = ansatz_dissipation(radius, width)
    assert 0.5 * (tensor[0, 0] + tensor[1, 1]) == pytest.approx(expected, rel=5e-3)
    assert tensor[0, 0] == pytest.approx(tensor[1, 1], rel=1e-6)
    assert abs(tensor[0, 1]) < 1e-6 * tensor[0, 0]


def test_thin_wall_estimate_is_the_large_skyrmion_limit_of_the_same_normalisation():
    """2π(R/Δ + Δ/R), the presets' 𝒟, approaches the ansatz's exact 𝒟 as R/Δ grows: the
    measured 𝒟 and the presets' estimate are the same quantity."""
    for ratio, tolerance in ((5, 0.08), (10, 0.04), (40, 0.01)):
        exact = ansatz_dissipation(ratio * 1e-9, 1e-9)
        assert thin_wall_dissipation(ratio * 1e-9, 1e-9) == pytest.approx(exact, rel=tolerance)


def test_radius_and_wall_width_are_recovered():
    film, centre, m = _ansatz(20e-9, 5e-9, cell=1e-9)
    material = load_micromagnetic_material("S2", cell_size=1e-9)
    iso = measure_isolated(m, film, material, energy=1e-19)
    assert iso.radius == pytest.approx(20e-9, rel=5e-3)
    r, mz = radial_profile(m, film, centre, 60e-9)
    assert fit_wall_width(r, mz, 20e-9) == pytest.approx(5e-9, rel=1e-2)
    assert iso.wall_width == pytest.approx(5e-9, rel=2e-2)
    # ∫(1 − m_z) dA of the ansatz, by quadrature
    rr = np.linspace(0, 100e-9, 200_001)
    s = math.sinh(20 / 5)
    sh = np.sinh(rr / 5e-9)
    deficit = np.trapezoid((1 - (sh**2 - s * s) / (sh**2 + s * s)) * 2 * np.pi * rr, rr)
    assert iso.moment_deficit == pytest.approx(deficit, rel=1e-2)


def test_a_texture_without_one_skyrmion_is_refused_in_one_line():
    film = Film(41, 41, 2e-9)
    uniform = skyrmion_texture(film, [], 10e-9, 3e-9)
    from skygas.core.errors import InputError

    with pytest.raises(InputError, match="isolated skyrmion"):
        measure_isolated(uniform, film, load_micromagnetic_material("S2"), 0.0)
