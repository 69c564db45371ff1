"""The force inference's parts against exact results, on tracks skygas's engine did not make.

Every statistical check compares with the truth within a number of the estimate's own standard
errors (stated at each assertion) or an ensemble of seeds: trajectories differ bit for bit between
CPUs, so no test may depend on one seed's luck.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from skygas.inference import dynamics, forces
from skygas.inference.basis import Axis, LandscapeBasis, RadialBasis
from skygas.inference.film import box_film, detect_periodic, field_of_view, tracks_leave
from skygas.inference.force_basis import ForceBasis, neighbour_pairs
from skygas.inference.tracks import load_tracks

from . import independent_gas as ig


def _frames(gas: ig.Gas, **options):
    spec = gas.spec
    return load_tracks(gas.tracks, spec.pixel_size, spec.frame_interval, **options)


def test_the_splines_fields_are_minus_the_gradient_and_their_divergence_minus_the_laplacian():
    rng = np.random.default_rng(3)
    basis = LandscapeBasis(Axis.covering(0.0, 1.0, 0.1), Axis.around(0.0, 1.0, 0.125))
    theta = rng.normal(size=basis.size)
    x, y = rng.uniform(0.1, 0.9, 50), rng.uniform(0, 1, 50)
    g = basis.fields(x, y)

    def u(px, py):
        return basis.values(px, py) @ theta

    e = 1e-5
    assert np.allclose(g.gx @ theta, -(u(x + e, y) - u(x - e, y)) / (2 * e), atol=1e-4)
    assert np.allclose(g.gy @ theta, -(u(x, y + e) - u(x, y - e)) / (2 * e), atol=1e-4)
    e = 1e-4
    laplacian = (u(x + e, y) + u(x - e, y) + u(x, y + e) + u(x, y - e) - 4 * u(x, y)) / e**2
    assert np.allclose(g.div @ theta, -laplacian, rtol=1e-3, atol=1e-2)
    # a periodic axis wraps: the same value one period on
    assert np.allclose(u(x, y), u(x, y + 1.0))
    # a radial basis: its derivative is the slope of its values, and it ends at hi
    radial = RadialBasis(1.0, 3.0, 8, logarithmic=True)
    r = np.linspace(0.5, 3.5, 31)
    value, slope = radial.evaluate(r)
    numeric = (radial.evaluate(r + 1e-7)[0] - radial.evaluate(r - 1e-7)[0]) / 2e-7
    assert np.allclose(slope, numeric, atol=1e-5)
    assert np.all(value[r >= 3.0] == 0)


def test_neighbour_pairs_match_all_pairs_with_the_minimum_image():
    rng = np.random.default_rng(4)
    n, frames, side = 30, 5, 10.0
    xy = rng.uniform(0, side, (frames, n, 2))
    from skygas.analysis.frames import Frames

    fr = Frames.from_dense(np.arange(frames), np.arange(n), xy[..., 0], xy[..., 1])
    film = box_film((side, side), (0.0, 0.0))
    i, j, dx, dy, r = neighbour_pairs(fr, film, 0, frames - 1, 2.5)
    for f in range(frames):
        d = xy[f][:, None, :] - xy[f][None, :, :]
        d -= side * np.round(d / side)
        dist = np.hypot(d[..., 0], d[..., 1])
        expected = np.count_nonzero((dist < 2.5) & (dist > 0))
        assert np.count_nonzero(fr.frame_of_entry[i] == f) == expected
    assert np.allclose(np.hypot(dx, dy), r) and r.max() < 2.5


def test_periodic_tracks_are_found_and_unwrapped():
    spec = ig.GasSpec(skyrmions=20, frames=300, width=10e-6, height=8e-6, boundary="periodic")
    gas = ig.simulate(spec)
    box = detect_periodic(_frames(gas, period=None, subtract_drift="no").frames)
    assert box is not None
    (lx, ly), _ = box
    assert lx == pytest.approx(10e-6, rel=0.01) and ly == pytest.approx(8e-6, rel=0.01)
    data = _frames(gas, subtract_drift="no")
    # unwrapped: every step is short, and the tracks follow the true positions
    a, b = data.frames.pairs_at_lag(1)
    assert np.max(np.abs(data.frames.x[b] - data.frames.x[a])) < 1e-6
    true = gas.true_positions[:, :, 0].T  # (particle, frame)
    order = np.lexsort((data.frames.frame_of_entry, data.frames.ids))
    shift = (true.ravel() - data.frames.x[order]).reshape(true.shape)
    # each track is the truth up to a constant offset of whole boxes (where it started)
    assert np.all(np.ptp(np.round(shift / lx), axis=1) == 0)
    assert np.allclose(shift, lx * np.round(shift / lx), atol=0.1 * lx)


def test_a_field_of_view_is_told_from_a_wall_by_tracks_that_leave():
    spec = ig.GasSpec(
        skyrmions=60,
        frames=300,
        width=40e-6,
        height=40e-6,
        field_of_view=(10e-6, 10e-6, 30e-6, 30e-6),
    )
    gas = ig.simulate(spec)
    frames = _frames(gas, subtract_drift="no").frames
    step = math.sqrt(2 * spec.diffusion * spec.frame_interval)
    assert tracks_leave(frames, field_of_view(frames, 0.0), step)
    walled = ig.simulate(spec.with_(field_of_view=None, boundary="walls", wall=(5.0, 1e-6)))
    frames = _frames(walled, subtract_drift="no").frames
    from skygas.physics.geometry import rectangle

    assert not tracks_leave(frames, rectangle(40e-6, 40e-6, center=(20e-6, 20e-6)), step)


def _moments(gas, basis_terms=("landscape",), walls=None, spacing=1.5e-6):
    spec = gas.spec
    frames = _frames(gas, subtract_drift="no").frames
    film = box_film((spec.width, spec.height), (0.0, 0.0))
    land = LandscapeBasis(
        Axis.around(0.0, spec.width, spacing), Axis.around(0.0, spec.height, spacing)
    )
    basis = ForceBasis(film, landscape=land if "landscape" in basis_terms else None)
    steps = dynamics.make_steps(frames, film)
    return dynamics.accumulate(frames, steps, basis), basis


def test_d_of_free_walks_with_localisation_error_within_3_standard_errors():
    spec = ig.GasSpec(
        skyrmions=40, frames=2000, width=30e-6, height=30e-6, boundary="periodic",
        localisation_error=50e-9,
    )  # fmt: skip
    gas = ig.simulate(spec)
    mom, basis = _moments(gas, basis_terms=())
    result = forces.fit_terms(mom, basis, [], 1.0)
    assert abs(result.diffusion - spec.diffusion) < 3 * result.diffusion_error
    assert result.diffusion_error < 0.03 * spec.diffusion
    # the localisation error from the lagged covariance of the steps: within 4 of its errors
    assert abs(math.sqrt(result.sigma2) - 50e-9) < 4 * result.sigma2_error / (2 * 50e-9)


def test_a_pinned_gas_gives_back_its_hall_angle_d_and_wells_within_its_errors():
    """Gaussian wells of 3 k_BT in a periodic box, Hall angle 60°, 20 nm localisation error.

    The Hall angle within 3 standard errors (or 2°), D within 3, the landscape correlated with
    the truth and its amplitude within 30 % (a 2000-frame movie: the map is noisy).
    """
    w = 30e-6
    spec = ig.GasSpec(
        skyrmions=60,
        frames=2000,
        width=w,
        height=w,
        boundary="periodic",
        hall_angle=math.radians(60),
        wells=ig.random_wells(40, w, w, 3.0, 1.5e-6, seed=3),
        localisation_error=20e-9,
        substeps=2,
    )
    gas = ig.simulate(spec)
    mom, basis = _moments(gas, spacing=0.75e-6)
    result = forces.infer_forces(mom, basis)
    assert "landscape" in result.terms
    hall, hall_err = result.jackknife(lambda f: f.hall_angle)
    assert abs(hall - spec.hall_angle) < max(3 * hall_err, math.radians(2))
    assert abs(result.diffusion - spec.diffusion) < 3 * result.diffusion_error
    x = np.linspace(0, w, 60)
    gx, gy = np.meshgrid(x, x)

    def centred(fit):
        u = basis.landscape.grid(x, x, result.coefficients("landscape", fit))
        return u - u.mean()

    u, error = result.jackknife(centred)
    truth = ig.landscape(spec, gx, gy)
    miss = u - (truth - truth.mean())
    # the map misses the truth by what its own errors say (rms of the misses in units of the
    # errors: 1 for honest errors; the smoothing's bias is allowed as much again)
    assert np.sqrt(np.mean((miss / error) ** 2)) < 2.0
    assert np.corrcoef(u.ravel(), truth.ravel())[0, 1] > 0.6


def test_a_free_gas_gets_no_landscape_and_no_interaction():
    spec = ig.GasSpec(skyrmions=40, frames=1500, width=30e-6, height=30e-6, boundary="periodic")
    gas = ig.simulate(spec)
    frames = _frames(gas, subtract_drift="no").frames
    from skygas.inference import candidates

    film = box_film((spec.width, spec.height), (0.0, 0.0))
    step = math.sqrt(2 * spec.diffusion * spec.frame_interval)
    basis = candidates.build(frames, film, step, pair="infer", walls="infer")
    steps = dynamics.make_steps(frames, film)
    result = forces.infer_forces(dynamics.accumulate(frames, steps, basis), basis)
    assert result.terms == ()
    assert not result.hall_angle_fixed
    assert abs(result.diffusion - spec.diffusion) < 3 * result.diffusion_error


def test_a_measured_map_is_the_map_where_sampled_and_smooth_where_it_ends(tmp_path):
    from skygas.engine import Simulation
    from skygas.physics.geometry import rectangle

    x = np.arange(60) * 10e-9
    gx, gy = np.meshgrid(x, x)
    values = 2 * np.sin(2 * np.pi * gx / 200e-9)
    values[:, 40:] = np.nan  # not sampled
    np.save(tmp_path / "map.npy", values)
    table = {
        "kind": "measured",
        "path": str(tmp_path / "map.npy"),
        "spacing": 10e-9,
        "correlation_length": 40e-9,
        "rms_kT": 0.5,
    }
    sim = Simulation(
        rectangle(590e-9, 590e-9, center=(295e-9, 295e-9)), "S2", landscape=[table], seed=2
    )
    grid, field = sim.wall_field.grid, sim.landscape
    kt = ig.BOLTZMANN * 300 * 1e21  # pN·nm
    nodes_x = grid.x0 + grid.spacing * np.arange(grid.nx)
    nodes_y = grid.y0 + grid.spacing * np.arange(grid.ny)
    row = np.argmin(np.abs(nodes_y - 300))
    sampled = (nodes_x > 20) & (nodes_x < 380)
    expected = 2 * np.sin(2 * np.pi * nodes_x[sampled] * 1e-9 / 200e-9)
    assert np.allclose(np.array(field.nodes[row, sampled, 0]) / kt, expected, atol=0.02)
    # no step where the map ends: a step of its 2 k_BT between two of the engine's nodes would
    # bend U by ~1.4 pN/nm; the blend into the disorder bends it no more than a few times the
    # sine's own curvature (the largest curvature sets a run's time step)
    own = 2 * (2 * np.pi / 200) ** 2 * kt  # the sine's largest curvature [pN/nm]
    assert field.max_curvature() < 10 * own
