"""Forces from trajectories and law fits, against trajectories made from known laws."""

import numpy as np
import pytest

from skygas.core.errors import InputError
from skygas.micromag import (
    DiskBoundary,
    Skyrmion,
    Trajectory,
    UnfixedLawError,
    fit_pair_law,
    fit_trajectories,
    fit_wall_law,
    pair_law_magnitude,
    synthetic,
    tabulate_law,
    thiele_forces,
    velocities,
    wall_law_magnitude,
)
from skygas.micromag.forces import PAIR_A2_FLOOR, law_problem
from skygas.micromag.workflow import thiele_coefficients
from skygas.physics.materials import load_material, preset, preset_names

FILM = 2e-9  # m
DISSIPATION = 20.0
PAPER_PAIR = (2.709, -5.643, 0.964)


@pytest.fixture(scope="module")
def system():
    material = preset("S2")
    coeffs = thiele_coefficients(-1.0, DISSIPATION, material, FILM)
    diameter = material.skyrmion_diameter
    return synthetic.ThieleSystem(
        coeffs["gyrocoupling"],
        coeffs["friction"],
        material.exchange_stiffness * FILM / diameter,
        diameter,
    )


def _trajectories(times, positions, radius):
    tracks = []
    for k in range(positions.shape[1]):
        track = Trajectory(k)
        for f, (t, (x, y)) in enumerate(zip(times, positions[:, k], strict=True)):
            track.add(f, t, Skyrmion(x, y, radius, -1.0, DISSIPATION, 0.0, 1.0, k + 1))
        tracks.append(track)
    return tracks


def test_thiele_forces_invert_the_equation_of_motion(system, rng):
    force = rng.normal(size=(10, 2)) * 1e-12
    back = thiele_forces(system.velocity(force), system.gyrocoupling, system.friction)
    np.testing.assert_allclose(back, force, rtol=1e-12, atol=1e-27)


def test_savitzky_golay_derivative_is_exact_for_a_cubic():
    t = np.linspace(0.0, 1e-8, 41)
    x = np.stack([3 + 2e8 * t - 1e16 * t**2 + 5e23 * t**3, -4e8 * t], axis=-1)
    expected = np.stack([2e8 - 2e16 * t + 15e23 * t**2, np.full_like(t, -4e8)], axis=-1)
    np.testing.assert_allclose(velocities(t, x, window=9, order=3), expected, rtol=1e-9)


def test_exact_samples_give_the_coefficients_back():
    d = np.linspace(1.0, 3.0, 30)
    fit = fit_pair_law(d, 2e-12 * pair_law_magnitude(d, PAPER_PAIR), 2e-12)
    np.testing.assert_allclose(fit.coefficients, PAPER_PAIR, rtol=1e-8)
    b = (0.3, -0.2, 1.1, -0.5)
    fit = fit_wall_law(d, 2e-12 * wall_law_magnitude(d, b), 2e-12, degree=3)
    np.testing.assert_allclose(fit.coefficients, b, rtol=1e-8)


def test_pair_law_fitted_back_from_a_two_skyrmion_trajectory(system, tmp_path):
    times = np.linspace(0.0, 60e-9, 601)
    start = [(-0.55 * system.skyrmion_diameter, 0.0), (0.55 * system.skyrmion_diameter, 0.0)]
    positions = synthetic.integrate_thiele(
        system, start, times, synthetic.pair_forces(system, PAPER_PAIR)
    )
    result = fit_trajectories(
        _trajectories(times, positions, system.skyrmion_diameter / 2), "S2", film_thickness=FILM
    )
    assert result.wall is None
    low, high = result.pair.distance_range
    assert low < 1.2 and high > 2.5  # the spiral covers the range the law is fitted over
    np.testing.assert_allclose(result.pair.coefficients, PAPER_PAIR, rtol=0.02)
    # The preset loads back through the engine's loader with the fitted coefficients.
    path = result.write(tmp_path)["material"]
    material = load_material(path)
    np.testing.assert_allclose(material.pair_law, result.pair.coefficients, rtol=1e-15)
    assert material.skyrmion_diameter == pytest.approx(system.skyrmion_diameter, rel=1e-15)
    assert material.dissipation == pytest.approx(DISSIPATION)
    assert material.topological_charge == -1
    assert (tmp_path / "fit.png").stat().st_size > 0


def test_wall_law_fitted_back_near_a_straight_wall(system):
    b = (0.5, 0.8, -0.3)
    wall = synthetic.straight_wall(0.0)
    times = np.linspace(0.0, 200e-9, 401)
    positions = synthetic.integrate_thiele(
        system,
        [(0.6 * system.skyrmion_diameter, 0.0)],
        times,
        synthetic.wall_forces(system, b, wall),
    )
    result = fit_trajectories(
        _trajectories(times, positions, system.skyrmion_diameter / 2),
        "S2",
        film_thickness=FILM,
        boundary=wall,
        wall_degree=2,
    )
    assert result.pair is None
    np.testing.assert_allclose(result.wall.coefficients, b, rtol=0.02)


def test_paper_wall_law_reproduced_in_a_disk(system):
    # The paper's degree-5 law in a 1024 nm disk: the coefficients of a degree-5 polynomial are
    # ill-conditioned, so the check is on the force curve over the sampled range.
    disk = DiskBoundary((0.0, 0.0), 512e-9)
    b = preset("S2").wall_law
    times = np.linspace(0.0, 400e-9, 801)
    start = [(512e-9 - 0.6 * system.skyrmion_diameter, 0.0)]
    positions = synthetic.integrate_thiele(
        system, start, times, synthetic.wall_forces(system, b, disk)
    )
    result = fit_trajectories(
        _trajectories(times, positions, system.skyrmion_diameter / 2),
        "S2",
        film_thickness=FILM,
        boundary=disk,
        wall_degree=5,
    )
    d = np.linspace(*result.wall.distance_range, 50)
    expected = system.force_scale * wall_law_magnitude(d, b)
    np.testing.assert_allclose(result.wall.magnitude(d), expected, rtol=0.01)
    assert result.wall.distance_range[1] > 2.5


def test_fit_input_errors():
    with pytest.raises(InputError, match="repulsive samples"):
        fit_pair_law([1.0, 2.0], [1e-12, 1e-13], 1e-12)
    with pytest.raises(InputError, match="force_scale"):
        fit_wall_law(np.arange(10.0), np.ones(10), 0.0)
    with pytest.raises(InputError, match="window"):
        velocities(np.arange(10.0), np.zeros((10, 2)), window=4)
    with pytest.raises(InputError, match="law"):
        fit_trajectories([], "S2", law="magic")


# --- Fitted laws must be usable by the engine ---------------------------------------------------


@pytest.mark.parametrize("name", preset_names())
def test_the_papers_laws_pass_the_check(name):
    """Every preset's pair law and the paper's wall law are bounded and decreasing where the
    engine uses them (S2's pair force peaks at 0.85 d_sk, below the checked range)."""
    material = preset(name)
    assert law_problem("pair", material.pair_law) is None
    assert law_problem("wall", material.wall_law) is None


def test_law_problems_are_named():
    assert "grows without bound" in law_problem("pair", (-0.05, 8.0, -1.0))
    assert "does not decay to zero" in law_problem("pair", (0.0, 8.0, -1.0))
    assert "grows without bound" in law_problem("wall", (-0.1, 3.0, 0.0))
    # a₂ > 0 but p(d) = (d² − 6d + 9)/(d + 1) falls for d < 3: the force rises from 1 to 3 d_sk
    assert "rises with distance at d = 1.00–3.00" in law_problem("pair", (1.0, -6.0, 9.0))
    assert "beyond 50 d_sk" in law_problem("pair", (0.01, 0.5, 0.0))


D_NARROW = np.linspace(1.2, 2.6, 40)  # d_sk: a narrow range, which fixes a₂ poorly


def test_pair_law_growing_outside_the_data_is_refitted_with_constraints():
    """Exact samples of a law with a₂ < 0 that decreases over the data: the free fit gives
    a₂ < 0 back, the constrained law (a₂ ≥ floor) passes the check and matches the data."""
    law = (-0.05, 8.0, -1.0)
    force = 2e-12 * pair_law_magnitude(D_NARROW, law)
    free = fit_pair_law(D_NARROW, force, 2e-12, check=False)
    np.testing.assert_allclose(free.coefficients, law, rtol=1e-6)
    fit = fit_pair_law(D_NARROW, force, 2e-12)
    assert fit.coefficients[0] >= PAIR_A2_FLOOR
    assert law_problem("pair", fit.coefficients) is None
    assert "a₂ ≥ 0.01" in fit.note and "grows without bound" in fit.note
    np.testing.assert_allclose(fit.magnitude(D_NARROW), force, rtol=0.01)
    assert fit.distance_range == pytest.approx((1.2, 2.6))


def test_pair_law_rising_inside_the_data_is_refused():
    force = 2e-12 * pair_law_magnitude(D_NARROW, (-1.0, 0.0, 0.0))  # F grows with d
    with pytest.raises(InputError, match="pair_law.*inside the data") as refused:
        fit_pair_law(D_NARROW, force, 2e-12)
    assert not isinstance(refused.value, UnfixedLawError)  # a data problem, not a range one


def test_pair_law_that_no_constraint_repairs_is_refused():
    # decreasing over the data but so slowly that no decaying law falls to 10⁻³ F₀ in 50 d_sk
    force = 2e-12 * pair_law_magnitude(D_NARROW, (-0.02, 0.5, 0.0))
    with pytest.raises(
        UnfixedLawError, match="pair_law.*do not fix how the force decays beyond 2.60 d_sk"
    ) as refused:
        fit_pair_law(D_NARROW, force, 2e-12)
    assert refused.value.fit.coefficients == pytest.approx((-0.02, 0.5, 0.0), abs=1e-6)


def test_wall_law_that_rises_is_refused():
    d = np.linspace(0.6, 3.0, 40)
    force = 2e-12 * wall_law_magnitude(d, (-0.2, 1.5, 0.0))  # leading coefficient < 0
    with pytest.raises(InputError, match="wall_law.*lower --wall-degree"):
        fit_wall_law(d, force, 2e-12, degree=2)


# --- The law tabulated over the measured range ---------------------------------------------------


def test_exact_samples_tabulate_on_the_law():
    """Bins of equal counts over unevenly spaced samples: a monotonic law maps each bin's
    median distance to its median force, so the table lies on the law."""
    d = 1.2 + 1.4 * np.linspace(0.0, 1.0, 49) ** 2  # dense at short distances
    force = 2e-12 * pair_law_magnitude(d, PAPER_PAIR)
    table = tabulate_law("pair", d, force, 40e-9, 2e-12)
    # ⌈√49⌉ = 7 bins of 7: odd counts, so each median is one of the samples
    assert table.count.tolist() == [7] * 7
    np.testing.assert_allclose(
        table.force, 2e-12 * pair_law_magnitude(table.distance, PAPER_PAIR), rtol=1e-12
    )
    assert table.distance_range == pytest.approx((1.2, 2.6))
    rows = table.rows()
    assert rows[0]["distance_m"] == pytest.approx(rows[0]["distance_diameters"] * 40e-9)
    assert rows[0]["force_over_F0"] == pytest.approx(rows[0]["force_N"] / 2e-12)
    assert tabulate_law("pair", d, force, 40e-9, 2e-12, bins=100).count.size == 49
    with pytest.raises(InputError, match="table bins"):
        tabulate_law("pair", d, force, 40e-9, 2e-12, bins=0)


def test_wall_law_not_fixed_beyond_the_data_leaves_the_table(system):
    """A wall law whose degree-2 fit grows without bound beyond the data: no law, no preset, one
    warning, the table on the true law; ``strict`` raises instead."""
    b = (-0.2, 1.5, 0.0)  # decreasing up to 3.75 d_sk, rising beyond
    wall = synthetic.straight_wall(0.0)
    times = np.linspace(0.0, 60e-9, 121)
    positions = synthetic.integrate_thiele(
        system,
        [(0.6 * system.skyrmion_diameter, 0.0)],
        times,
        synthetic.wall_forces(system, b, wall),
    )
    tracks = _trajectories(times, positions, system.skyrmion_diameter / 2)
    result = fit_trajectories(tracks, "S2", film_thickness=FILM, boundary=wall, wall_degree=2)
    assert result.wall is None and result.material is None
    assert set(result.unfixed) == {"wall"}
    (warning,) = result.warnings
    assert warning.startswith("wall law: the samples (d = 0.60–") and "no material.toml" in warning
    assert "refit with a lower --wall-degree (now 2)" in warning
    table = result.tables["wall"]
    np.testing.assert_allclose(
        table.force, system.force_scale * wall_law_magnitude(table.distance, b), rtol=0.01
    )
    assert "wall law" in result.no_material_reason
    with pytest.raises(UnfixedLawError, match="wall_law"):
        fit_trajectories(
            tracks, "S2", film_thickness=FILM, boundary=wall, wall_degree=2, strict=True
        )


def test_a_pair_law_rising_inside_the_data_is_refused_without_strict(system):
    times = np.linspace(0.0, 5e-9, 41)
    start = [(-0.6 * system.skyrmion_diameter, 0.0), (0.6 * system.skyrmion_diameter, 0.0)]
    positions = synthetic.integrate_thiele(
        system, start, times, synthetic.pair_forces(system, (-1.0, 0.0, 0.0))
    )
    tracks = _trajectories(times, positions, system.skyrmion_diameter / 2)
    with pytest.raises(InputError, match="inside the data") as refused:
        fit_trajectories(tracks, "S2", film_thickness=FILM)
    assert not isinstance(refused.value, UnfixedLawError)


def test_law_formulas_name_every_coefficient_highest_power_first():
    from skygas.micromag.forces import law_coefficient_names, law_formula

    assert law_formula("pair", 3) == "|F|(d) = F₀·exp[−(a₂d² + a₁d + a₀)/(d + 1)]"
    assert law_formula("wall", 4) == "|F|(d) = F₀·exp[−(b₃d³ + b₂d² + b₁d + b₀)]"
    assert law_coefficient_names("wall", 6) == ("b₅", "b₄", "b₃", "b₂", "b₁", "b₀")
    # the form evaluates to the law the engine uses: exp[−polyval(b, d)] at d = 2
    b = (0.5, -1.0, 2.0, 0.25)
    by_formula = np.exp(-(b[0] * 2**3 + b[1] * 2**2 + b[2] * 2 + b[3]))
    np.testing.assert_allclose(by_formula, wall_law_magnitude(2.0, b))
