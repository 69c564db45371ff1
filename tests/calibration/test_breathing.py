"""The breathing measurement's pieces against analytic results, without a solver.

The field scan's plan, 𝒟_RR of the 360° wall ansatz (its textures at two radii, differenced
on a mesh, against a quadrature of ∂_R θ written here, and its thin-wall limit 4πR/Δ), the
Lagrange-multiplier integral of E_self on a self-energy known in closed form, the shift fit on an
exponential law shifted by a known amount, the shifts from squeezed radii in balance, and the
model's choice. The measurement on a real
calibration is tested in test_calibrate_cli.py (the module of the shared calibration).
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy import integrate

from skygas.calibration import breathing, plan
from skygas.calibration.laws import EnergyCurve
from skygas.calibration.solver import Film, skyrmion_texture


def test_the_scan_aims_at_its_radii_and_stops_at_its_largest_field():
    # d ln R/dB = −7.2 /T (S6's 0.72 % per mT): the offsets that aim at each relative change
    fields = plan.scan_fields(-7.2)
    assert [t for _, t in fields] == list(plan.SCAN_TARGETS)
    for field_T, target in fields:
        assert field_T == pytest.approx(target / -7.2)
    assert plan.shifted_field(-7.2) == pytest.approx(plan.SHIFTED_TARGET / -7.2)
    # a stiff skyrmion: every offset capped at SCAN_MAX_FIELD
    assert {abs(f) for f, _ in plan.scan_fields(-0.1)} == {plan.SCAN_MAX_FIELD}
    # a radius that grows with the field along the background is no skyrmion to scan
    assert plan.scan_fields(0.5) == [] and plan.shifted_field(0.0) is None


def _dr_theta_integral(radius: float, width: float) -> float:
    """2π∫(∂_R θ)² r dr of θ = 2 atan[sinh(R/Δ)/sinh(r/Δ)], ∂_R θ by a central difference."""
    h = 1e-6 * radius

    def theta(r, big_r):
        return 2 * math.atan2(math.sinh(big_r / width), math.sinh(r / width))

    def integrand(r):
        return ((theta(r, radius + h) - theta(r, radius - h)) / (2 * h)) ** 2 * r

    return 2 * math.pi * integrate.quad(integrand, 0, radius + 40 * width, points=[radius])[0]


@pytest.mark.parametrize("radius, width", [(15e-9, 3e-9), (30e-9, 4e-9), (8e-9, 3e-9)])
def test_radius_dissipation_of_the_ansatz_is_its_integral(radius, width):
    assert breathing.ansatz_radius_dissipation(radius, width) == pytest.approx(
        _dr_theta_integral(radius, width), rel=1e-6
    )


def test_the_thin_wall_limit_is_four_pi_r_over_delta():
    # a thin wall: the 180° wall's ∫θ'² dr = 2/Δ on a circle of 2πR
    assert breathing.ansatz_radius_dissipation(50e-9, 1e-9) == pytest.approx(
        4 * math.pi * 50, rel=1e-3
    )


def test_differenced_textures_on_a_mesh_give_the_ansatz_integral():
    """The measured 𝒟_RR's discretisation: ansatz textures at R ± δ on 0.5 nm cells."""
    radius, width, cell = 12e-9, 3e-9, 0.5e-9
    film = Film(121, 121, cell)
    centre = (0.5 * film.size[0], 0.5 * film.size[1])
    step = 0.02 * radius
    plus = skyrmion_texture(film, [centre], radius + step / 2, width)
    minus = skyrmion_texture(film, [centre], radius - step / 2, width)
    x, y = film.centres()
    region = np.hypot(x - centre[0], y - centre[1]) <= 25e-9
    measured = breathing.difference_dissipation(plus, minus, step, cell, region)
    assert measured == pytest.approx(_dr_theta_integral(radius, width), rel=0.02)


def test_the_multiplier_integral_recovers_a_known_self_energy():
    """E_self(A) = ½κ(A − A₀)²: the field that holds A is B = −κ(A − A₀)/(M_s t)."""
    ms_t, kappa, a0 = 2e-3, 4e10, 9e-16
    areas = a0 * np.array([0.6, 0.8, 0.99, 1.0, 1.01, 1.25, 1.5])
    points = [
        {
            "moment_deficit_m2": a,
            "field_T": -kappa * (a - a0) / ms_t,
            "energy_J": 0.5 * kappa * (a - a0) ** 2 - 1e-20,
        }
        for a in areas
    ]
    integrated = breathing.integrated_energies(points, ms_t)
    expected = [p["energy_J"] for p in points]
    assert integrated == pytest.approx(expected, rel=1e-9, abs=1e-12 * kappa * a0**2)


def test_the_shift_fit_recovers_a_known_shift_of_an_exponential_law():
    decay, shift, per_unit = 10e-9, 1.3, -3e-9  # 2ΔR = −3 nm: a skyrmion 1.5 nm smaller
    d = np.linspace(20e-9, 140e-9, 13)
    curve = EnergyCurve(d, 1e-19 * np.exp(-d / decay))
    at = np.array([28e-9, 32e-9, 40e-9])
    energy = 1e-19 * np.exp(-(at - shift * per_unit) / decay)
    fit = breathing.fit_shift(curve, at, energy, per_unit)
    assert fit["shift"] == pytest.approx(shift, abs=1e-3)
    assert fit["rms_log_residual"] < 1e-3
    # unshifted, every ln E is off by s·|2ΔR|/λ
    assert fit["rms_log_residual_unshifted"] == pytest.approx(shift * 3e-9 / decay, rel=1e-3)
    assert fit["shift_per_point"] == pytest.approx([shift] * 3, abs=1e-3)


def _skyrmion(x: float, radius: float) -> dict:
    return {"x": x, "y": 50e-9, "radius": radius, "charge": -1.0}


def test_the_squeeze_fit_recovers_known_shifts_from_the_balance_of_the_radius():
    """Pairs and edge singles whose radii are those where the breathing model's radius is in
    balance, −E_self'(R) = s·F, for a harmonic E_self and exponential laws: the fit gives
    back s_p and s_w (the film's centre single 0.2 nm off the table's R₀, as a finite film
    leaves it, is taken as its R₀)."""
    from types import SimpleNamespace

    r0, k, s_p, s_w, film_offset = 11.6e-9, 6e-4, 1.25, 0.9, 0.2e-9
    radius = np.linspace(0.7 * r0, 1.3 * r0, 25)
    energy = 0.5 * k * (radius - r0) ** 2
    pair = lambda d: 3e-12 * np.exp(-np.asarray(d) / 8e-9)  # noqa: E731 - force laws [N]
    wall = lambda x: 2e-12 * np.exp(-np.asarray(x) / 5e-9)  # noqa: E731
    results = {"laws/single/9": {"skyrmions": [_skyrmion(300e-9, r0 + film_offset)]}}
    for i, x in enumerate([20e-9, 25e-9, 30e-9]):  # edge singles, squeezed by the edge
        squeezed = r0 - s_w * float(wall(x)) / k
        results[f"laws/single/{i}"] = {"skyrmions": [_skyrmion(x, squeezed + film_offset)]}
    for i, d in enumerate([26e-9, 30e-9, 36e-9, 45e-9]):  # pairs, squeezed by each other
        squeezed = r0 - s_p * float(pair(d)) / k + film_offset
        results[f"laws/pair/{i}"] = {
            "skyrmions": [_skyrmion(150e-9, squeezed), _skyrmion(150e-9 + d, squeezed)]
        }
    job = SimpleNamespace(results=results)
    cal = SimpleNamespace(pair=pair, wall=wall, isolated=SimpleNamespace(radius=r0))
    fit = breathing.squeeze_shifts(job, cal, radius, energy)
    assert fit["pair"]["shift"] == pytest.approx(s_p, rel=1e-6)
    assert fit["wall"]["shift"] == pytest.approx(s_w, rel=1e-6)
    assert fit["pair"]["shift_per_point"] == pytest.approx([s_p] * 4, rel=1e-6)
    assert fit["pair"]["distance_m"] == pytest.approx([26e-9, 30e-9, 36e-9, 45e-9])


def test_the_choice_follows_the_sensitivity_against_the_threshold():
    threshold = breathing.BREATHING_SENSITIVITY
    soft, why = breathing.choose({"relative_change_per_mT": -1.5 * threshold})
    assert soft == "breathing" and f"{1.5 * threshold * 100:.2f} % per mT" in why
    stiff, why = breathing.choose({"relative_change_per_mT": -0.5 * threshold})
    assert stiff == "rigid" and f"at most {threshold * 100:g} % per mT" in why
    assert breathing.choose({})[0] == "rigid"
