"""Observables of skygas.analysis against exact results.

Statistical checks use 4 standard errors (a correct estimator fails one with probability
≈ 6×10⁻⁵; seeds are fixed, so the suite is deterministic). Where the standard error is derived
rather than estimated, the derivation is given beside the test.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
import shapely

# the engine tests' helpers: lattice(n_side, spacing_nm) [nm], the 2×2 drift solve, no pairs
from engine.test_dynamics import NO_PAIRS, drift_solution, lattice  # noqa: E402
from skygas.analysis import (
    Frames,
    density_map,
    hall_angle,
    mean_squared_displacement,
    mean_velocity,
    occupancy,
    pair_correlation,
)
from skygas.analysis.structure import isotropic_covariogram
from skygas.engine import Simulation
from skygas.physics.geometry import disk, rectangle
from skygas.physics.materials import derive_thiele, preset

S2 = preset("S2")


# -- the frame table ------------------------------------------------------------------------
def test_pairs_at_lag_match_the_same_skyrmion_across_gaps():
    rng = np.random.default_rng(1)
    present = rng.random((30, 12)) < 0.6  # skyrmions come and go
    x = np.where(present, rng.normal(size=present.shape), np.nan)
    frames = Frames.from_dense(np.arange(30) * 1e-9, np.arange(100, 112), x, x * 2)
    for lag in (1, 3, 7):
        a, b = frames.pairs_at_lag(lag)
        fa, fb = frames.frame_of_entry[a], frames.frame_of_entry[b]
        assert np.all(fb - fa == lag) and np.all(frames.ids[a] == frames.ids[b])
        expected = np.sum(present[:-lag] & present[lag:])
        assert len(a) == expected


def test_uneven_frames_are_refused_for_lag_observables():
    frames = Frames.from_dense([0.0, 1e-9, 3e-9], [0], [[0.0], [1.0], [2.0]], [[0.0], [0.0], [0.0]])
    with pytest.raises(ValueError, match="evenly"):
        mean_squared_displacement(frames)


# -- diffusion constant ---------------------------------------------------------------------
@pytest.mark.slow
def test_free_diffusion_constant_from_the_msd():
    """400 non-interacting skyrmions 500 nm apart in a 16 µm square, > 5 µm from walls,
    recorded every 5 ns for 60 ns (rms displacement ≈ 100 nm ≪ spacing and wall distance).

    Lag-1 displacements are independent; |Δr|²/(4DΔ) is exponential with unit mean and
    variance, so the lag-1 estimate D₁ = MSD(Δ)/(4Δ) has the exact relative standard error
    1/√n over n displacements. The jackknife error must reproduce it, and D fitted over the
    first lags must agree with the exact D within 4 of its jackknife errors."""
    temperature = 300.0
    exact = derive_thiele(S2).diffusion_constant(temperature)
    sim = Simulation(
        rectangle(16e-6, 16e-6), S2, temperature=temperature, seed=3, grid_spacing=30e-9, **NO_PAIRS
    )
    sim.add_skyrmions(lattice(20, 500.0) * 1e-9)
    sim.run(60e-9, record_interval=5e-9)
    frames = Frames.from_trajectories(sim.trajectories())
    lag1 = mean_squared_displacement(frames, lags=[1], fit_lags=[1])
    n = lag1.n_pairs[0]
    sigma = exact / math.sqrt(n)
    assert n == 400 * (frames.n_frames - 1)
    assert abs(lag1.diffusion_constant - exact) < 4 * sigma, (lag1.diffusion_constant, exact)
    assert lag1.diffusion_error == pytest.approx(sigma, rel=0.25)
    fitted = mean_squared_displacement(frames, lags=[1, 2, 3, 4])
    assert abs(fitted.diffusion_constant - exact) < 4 * fitted.diffusion_error
    assert fitted.diffusion_error < 0.05 * exact  # a sharp check, not a loose one
    # the MSD itself is linear: 4Dτ at every lag within its errors
    assert np.all(np.abs(fitted.msd - 4 * exact * fitted.lag_time) < 4 * fitted.msd_error)


# -- g(r) ----------------------------------------------------------------------------------
def test_covariogram_of_a_disk_is_exact():
    """γ(r) = 2R² acos(r/2R) − (r/2)√(4R² − r²) for a disk of radius R (the lens area)."""
    radius = 500.0
    region = shapely.Point(0, 0).buffer(radius, quad_segs=256)
    r = np.array([0.0, 100.0, 400.0, 900.0])
    exact = 2 * radius**2 * np.arccos(r / (2 * radius)) - r / 2 * np.sqrt(4 * radius**2 - r**2)
    np.testing.assert_allclose(isotropic_covariogram(region, r, 8), exact, rtol=2e-4)


def test_pair_correlation_of_an_ideal_gas_is_one_at_every_distance():
    """Uniform independent points in a disk of 1 µm diameter (walls included) give g(r) = 1
    for all r. Each bin must lie within 4.5 of its jackknife errors (20 blocks: a Student t
    with 19 degrees of freedom exceeds 4.5 with probability 2.4×10⁻⁴, so one of 30 bins does
    with < 1 %); the errors must be close to those of 500 independent frames, which the block
    scatter measures, and far from the Poisson error, which ignores shared points."""
    outline = disk(diameter=1e-6)
    rng = np.random.default_rng(7)
    frames_xy = []
    for _ in range(500):
        pts = np.empty((0, 2))
        while len(pts) < 60:
            cand = rng.uniform(-500, 500, size=(200, 2))
            pts = np.vstack([pts, cand[outline._contains_nm(cand[:, 0], cand[:, 1])]])
        frames_xy.append(pts[:60] * 1e-9)
    xy = np.concatenate(frames_xy)
    frames = Frames(
        np.arange(500) * 1e-9, np.full(500, 60), np.tile(np.arange(60), 500), xy[:, 0], xy[:, 1]
    )
    result = pair_correlation(frames, outline, r_max=0.9e-6, bins=30, max_frames=500)
    assert np.all(np.abs(result.g - 1) < 4.5 * result.error), (result.g, result.error)
    assert np.all(result.error < 0.05)
    # without the confinement correction the large distances would be far below 1
    r_nm, width_nm = result.r * 1e9, np.diff(result.edges)[0] * 1e9
    bulk = 500 * 60 * 59 / 2 * 2 * np.pi * r_nm * width_nm / outline.region.area
    assert result.expected[-1] < 0.1 * bulk[-1]


# -- Hall angle -----------------------------------------------------------------------------
def test_hall_angle_of_a_uniform_drift_is_the_thiele_solution():
    thiele = derive_thiele(S2, eta=2.5 * S2.damping)
    v_s = np.array([15.0, 4.0])
    sim = Simulation(
        rectangle(6e-6, 6e-6),
        S2,
        temperature=0.0,
        thiele=thiele,
        drift_velocity=v_s,
        grid_spacing=30e-9,
        **NO_PAIRS,
    )
    sim.add_skyrmions(lattice(3, 600.0) * 1e-9 - [1e-6, 0.0])
    sim.run(100e-9, record_interval=10e-9)
    v = mean_velocity(Frames.from_trajectories(sim.trajectories()))
    expected = drift_solution(thiele, v_s)
    np.testing.assert_allclose(v.velocity, expected, rtol=1e-8)
    angle = v.hall_angle(v_s)
    assert angle == pytest.approx(
        math.atan2(expected[1], expected[0]) - math.atan2(v_s[1], v_s[0]), abs=1e-8
    )
    assert angle == pytest.approx(thiele.hall_angle(), abs=1e-8)
    assert abs(angle) > 0.05


def test_hall_angle_with_thermal_noise_within_its_error():
    thiele = derive_thiele(S2, eta=2 * S2.damping)
    v_s = np.array([20.0, 0.0])
    sim = Simulation(
        rectangle(16e-6, 16e-6),
        S2,
        temperature=300.0,
        thiele=thiele,
        drift_velocity=v_s,
        seed=9,
        grid_spacing=30e-9,
        **NO_PAIRS,
    )
    sim.add_skyrmions(lattice(12, 700.0) * 1e-9)
    sim.run(100e-9, record_interval=10e-9)
    v = mean_velocity(Frames.from_trajectories(sim.trajectories()))
    expected = drift_solution(thiele, v_s)
    assert np.all(np.abs(v.velocity - expected) < 4 * v.error), (v.velocity, expected, v.error)
    exact_angle = thiele.hall_angle()
    assert abs(v.hall_angle(v_s) - exact_angle) < 4 * v.hall_angle_error(v_s)
    assert hall_angle([1.0, 1.0], [1.0, 0.0]) == pytest.approx(math.pi / 4)


# -- maps and occupancy -----------------------------------------------------------------------
def test_density_map_integrates_to_the_mean_count():
    rng = np.random.default_rng(2)
    n_frames, n = 50, 40
    xy = rng.uniform(0, 1e-6, size=(n_frames * n, 2))
    frames = Frames(
        np.arange(n_frames) * 1e-9,
        np.full(n_frames, n),
        np.tile(np.arange(n), n_frames),
        xy[:, 0],
        xy[:, 1],
    )
    m = density_map(frames, 10, (0, 1e-6, 0, 1e-6))
    cell = (m.x_edges[1] - m.x_edges[0]) * (m.y_edges[1] - m.y_edges[0])
    assert m.values.sum() * cell == pytest.approx(n)
    occ = occupancy(frames, lambda x, y: (x > 0.5e-6).astype(int), ("left", "right"))
    assert occ["mean_total"] == n
    assert np.all(np.array(occ["left"]) + np.array(occ["right"]) == n)
