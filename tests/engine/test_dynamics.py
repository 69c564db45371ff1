"""Engine physics against exact results (docs/physics.md §1), with stated statistical tolerances.

Statistical assertions use "4 standard errors" unless stated otherwise: for a correct engine a
single check fails with probability ≈ 6×10⁻⁵; the seeds are fixed, so the suite is
deterministic, but the tolerances are what a fresh seed would need.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy import integrate, stats

from skygas.core import units
from skygas.engine import INTEGRATOR_ORDERS, Simulation
from skygas.physics.forces import wall_potential
from skygas.physics.geometry import disk, rectangle
from skygas.physics.materials import derive_thiele, preset

S2 = preset("S2")
NO_PAIRS = {"pair_law": "lin-reichhardt", "pair_law_params": {"amplitude": 0.0}}


def lattice(n_side: int, spacing_nm: float) -> np.ndarray:
    """n_side² points [nm] on a square lattice centred on the origin."""
    c = (np.arange(n_side) - (n_side - 1) / 2) * spacing_nm
    gx, gy = np.meshgrid(c, c)
    return np.column_stack([gx.ravel(), gy.ravel()])


def displacements(sim: Simulation, duration: float, n_intervals: int) -> np.ndarray:
    """Displacement vectors [nm] of every skyrmion over ``n_intervals`` successive intervals."""
    out = []
    for _ in range(n_intervals):
        _, start = sim.positions()
        sim.run(duration)
        _, end = sim.positions()
        out.append((end - start) * units.M_TO_NM)
    return np.concatenate(out)


# -- free diffusion ------------------------------------------------------------------------
@pytest.mark.parametrize("antiferromagnetic", [False, True])
def test_free_diffusion_msd_is_4Dt(antiferromagnetic):
    material = S2.antiferromagnetic_variant() if antiferromagnetic else S2
    thiele = derive_thiele(material)
    a, g = thiele.friction, thiele.gyrocoupling
    d_exact = units.BOLTZMANN * 300.0 * a / (a * a + g * g) * units.M2_PER_S_TO_NM2_PER_NS
    # Skyrmions 500 nm apart (pair cutoff ≈ 194 nm) and > 1 µm from walls: they are free
    # as long as the rms displacement stays well below ~300 nm.
    interval = 60e-9 if not antiferromagnetic else 3e-9
    sim = Simulation(
        rectangle(16e-6, 16e-6), material, temperature=300.0, seed=11, grid_spacing=30e-9
    )
    sim.add_skyrmions(lattice(28, 500.0) * 1e-9)
    dx = displacements(sim, interval, 6)
    sq = np.sum(dx**2, axis=1)
    t_ns = interval * units.S_TO_NS
    d_est = sq.mean() / (4 * t_ns)
    se = sq.std(ddof=1) / math.sqrt(len(sq)) / (4 * t_ns)
    assert abs(d_est - d_exact) < 4 * se, (d_est, d_exact, se)
    assert se / d_exact < 0.02  # the check is sharp: 4 SE is below 8 % of D
    # each axis diffuses with D (isotropy), and the mean displacement vanishes
    for axis in range(2):
        var = np.mean(dx[:, axis] ** 2) / (2 * t_ns)
        assert abs(var - d_exact) < 4 * math.sqrt(2 / len(dx)) * d_exact
        assert abs(dx[:, axis].mean()) < 4 * math.sqrt(2 * d_exact * t_ns / len(dx))


def test_antiferromagnetic_diffusion_ratio_is_exact():
    fm = derive_thiele(S2)
    afm = derive_thiele(S2.antiferromagnetic_variant())
    g_tilde = fm.gyrocoupling / fm.k
    alpha_d = fm.damping * fm.dissipation
    ratio = afm.diffusion_constant(300) / fm.diffusion_constant(300)
    assert ratio == pytest.approx((g_tilde**2 + alpha_d**2) / alpha_d**2, rel=1e-12)


# -- drift and Hall angle ----------------------------------------------------------------------
def drift_solution(thiele, v_s) -> np.ndarray:
    """Velocity from solving (G ε + α𝒟k I)·v = μ (G ε + η𝒟k I)·v_s directly."""
    eps = np.array([[0.0, 1.0], [-1.0, 0.0]])
    lhs = thiele.gyrocoupling * eps + thiele.friction * np.eye(2)
    rhs = thiele.mu * (
        thiele.gyrocoupling * eps + thiele.eta * thiele.dissipation * thiele.k * np.eye(2)
    )
    return np.linalg.solve(lhs, rhs @ np.asarray(v_s))


@pytest.mark.parametrize("eta_factor", [1.0, 2.0, 0.3])
def test_uniform_drift_matches_thiele_solution_at_zero_temperature(eta_factor):
    thiele = derive_thiele(S2, eta=eta_factor * S2.damping, mu=0.8)
    v_s = np.array([12.0, -5.0])  # m/s
    sim = Simulation(
        rectangle(6e-6, 6e-6),
        S2,
        temperature=0.0,
        thiele=thiele,
        drift_velocity=v_s,
        grid_spacing=30e-9,
    )
    sim.add_skyrmions([[-1e-6, 0.0]])
    _, start = sim.positions()
    sim.run(100e-9)
    _, end = sim.positions()
    velocity = (end - start)[0] / sim.time
    expected = drift_solution(thiele, v_s)
    np.testing.assert_allclose(velocity, expected, rtol=1e-9)
    if eta_factor == 1.0:
        np.testing.assert_allclose(velocity, thiele.mu * v_s, rtol=1e-9)
    else:
        angle = math.atan2(velocity[1], velocity[0]) - math.atan2(v_s[1], v_s[0])
        assert angle == pytest.approx(thiele.hall_angle(), abs=1e-9)
        assert abs(angle) > 0.05  # a real skyrmion Hall angle, not a trivial zero


def test_drift_with_noise_has_the_thiele_mean_velocity():
    thiele = derive_thiele(S2, eta=2 * S2.damping)
    v_s = np.array([20.0, 0.0])
    sim = Simulation(
        rectangle(16e-6, 16e-6),
        S2,
        temperature=300.0,
        thiele=thiele,
        drift_velocity=v_s,
        seed=5,
        grid_spacing=30e-9,
    )
    sim.add_skyrmions(lattice(20, 500.0) * 1e-9)
    duration = 100e-9
    dx = displacements(sim, duration, 1) * 1e-9  # m
    velocity = dx.mean(axis=0) / duration
    expected = drift_solution(thiele, v_s)
    d = thiele.diffusion_constant(300.0)
    se = math.sqrt(2 * d * duration / len(dx)) / duration
    assert np.all(np.abs(velocity - expected) < 4 * se), (velocity, expected, se)


# -- Boltzmann equilibrium despite the gyrotropic term ----------------------------------------
def test_single_skyrmion_in_disk_samples_boltzmann_density():
    """Non-interacting skyrmions in a disk of radius R: the density of the distance r from the
    centre must be ∝ r·exp(−U_wall(R − r)/k_B T), U_wall the integral of the wall law.

    The dissipation is chosen so that α𝒟 = |G̃|: the gyrotropic term is as strong as the
    dissipative one, yet it must not change the stationary distribution."""
    radius_nm = 100.0
    n = 300
    g_tilde = 4 * math.pi
    thiele = derive_thiele(S2, dissipation=g_tilde / S2.damping)
    sim = Simulation(
        disk(diameter=2 * radius_nm * 1e-9),
        S2,
        temperature=300.0,
        thiele=thiele,
        seed=3,
        time_step=1e-10,
        **NO_PAIRS,
    )
    rng = np.random.default_rng(0)
    r0 = radius_nm * 0.6 * np.sqrt(rng.uniform(size=n))
    phi = rng.uniform(0, 2 * np.pi, size=n)
    sim.add_skyrmions(np.column_stack([r0 * np.cos(phi), r0 * np.sin(phi)]) * 1e-9, validate=False)
    d_diff = thiele.diffusion_constant(300.0) * units.M2_PER_S_TO_NM2_PER_NS
    relax_ns = radius_nm**2 / d_diff  # a few relaxation times of the radial coordinate
    sim.run(relax_ns * 1e-9)
    samples = []
    for _ in range(5):  # frames half a relaxation time apart: nearly independent samples
        sim.run(0.5 * relax_ns * 1e-9)
        _, pos = sim.positions()
        samples.append(np.hypot(pos[:, 0], pos[:, 1]) * units.M_TO_NM)
    r = np.concatenate(samples)

    d_sk = thiele.skyrmion_diameter_internal
    kt = units.thermal_energy_internal(300.0)
    u_scale = thiele.force_scale_internal * d_sk / kt
    grid = np.linspace(0, radius_nm, 2001)
    density = grid * np.exp(-u_scale * wall_potential((radius_nm - grid) / d_sk, S2.wall_law))
    cdf = integrate.cumulative_trapezoid(density, grid, initial=0.0)
    cdf /= cdf[-1]
    ks = stats.kstest(r, lambda x: np.interp(x, grid, cdf))
    assert ks.pvalue > 1e-3, ks
    # the wall potential matters: the density differs clearly from the uniform disk's
    uniform = stats.kstest(r, lambda x: np.clip(x / radius_nm, 0, 1) ** 2)
    assert uniform.pvalue < 1e-6


# -- deterministic dynamics --------------------------------------------------------------------
def spiral_angle(points: np.ndarray) -> np.ndarray:
    return np.unwrap(np.arctan2(points[:, 1], points[:, 0]))


def test_two_skyrmions_spiral_apart_on_the_exact_log_spiral():
    """At T = 0 the separation ρ obeys dρ/dt = 2aF/(a²+g²), ρ dθ/dt = 2gF/(a²+g²) for any
    repulsive F(ρ): a logarithmic spiral θ − θ₀ = (G/α𝒟k) ln(ρ/ρ₀), anticlockwise for G > 0."""
    sim = Simulation(disk(diameter=6e-6), S2, temperature=0.0, time_step=5e-12, grid_spacing=20e-9)
    d_sk = sim.thiele.skyrmion_diameter_internal
    sim.add_skyrmions(np.array([[-0.6 * d_sk, 0.0], [0.6 * d_sk, 0.0]]) * 1e-9)
    sim.run(60e-9, record_interval=0.5e-9)
    ds = sim.trajectories()
    rel = np.column_stack([ds.x[:, 1] - ds.x[:, 0], ds.y[:, 1] - ds.y[:, 0]]) * units.M_TO_NM
    rho = np.hypot(rel[:, 0], rel[:, 1])
    theta = spiral_angle(rel)
    assert np.all(np.diff(rho) > 0)  # they repel
    assert rho[-1] > 2.5 * d_sk
    pitch = sim.thiele.gyrocoupling / sim.thiele.friction
    expected = pitch * np.log(rho / (1.2 * d_sk))
    np.testing.assert_allclose(theta - 0.0, expected, atol=2e-4 * abs(expected[-1]) + 1e-6)
    assert theta[-1] > 1.0  # anticlockwise, and well over a radian


def test_skyrmion_at_wall_moves_along_and_away_clockwise():
    """Paper, boundary figure: a skyrmion 50 nm from the wall of a 1024 nm disk moves along
    the wall and away from it, clockwise. The wall force is radial, so the path is the log
    spiral θ − θ₀ = (G/α𝒟k) ln(r/r₀) with r decreasing: clockwise for G > 0."""
    sim = Simulation(disk(diameter=1024e-9), S2, temperature=0.0, time_step=1e-11)
    sim.add_skyrmions([[462e-9, 0.0]])
    sim.run(200e-9, record_interval=1e-9)
    ds = sim.trajectories()
    pos = np.column_stack([ds.x[:, 0], ds.y[:, 0]]) * units.M_TO_NM
    r = np.hypot(pos[:, 0], pos[:, 1])
    theta = spiral_angle(pos)
    assert np.all(np.diff(r) < 0)  # away from the wall
    assert np.all(np.diff(theta) < 0)  # clockwise
    assert r[-1] < 400.0
    pitch = sim.thiele.gyrocoupling / sim.thiele.friction
    expected = pitch * np.log(r / 462.0)
    # the polygonal disk's facets tilt the interpolated normal by ≲ 0.02 rad
    np.testing.assert_allclose(theta, expected, rtol=0.02, atol=1e-3)


# -- convergence ---------------------------------------------------------------------------------
def final_positions(integrator, dt, temperature=0.0, substeps=1, seed=0):
    sim = Simulation(
        disk(diameter=800e-9),
        S2,
        temperature=temperature,
        time_step=dt,
        seed=seed,
        integrator=integrator,
        brownian_substeps=substeps,
    )
    rng = np.random.default_rng(42)
    from skygas.physics.geometry import _random_positions_nm

    d_sk = sim.thiele.skyrmion_diameter_internal
    pts = _random_positions_nm(sim.outline, 20, 1.05 * d_sk, 0.5 * d_sk, rng)
    sim.state.insert_nm(pts)
    sim.run(4e-9)
    return sim.positions()[1] * units.M_TO_NM


def convergence_slope(integrator, temperature, steps, ref_dt):
    errors = []
    ref = final_positions(integrator, ref_dt, temperature, 1)
    for dt in steps:
        k = int(round(dt / ref_dt))
        x = final_positions(integrator, dt, temperature, k)
        errors.append(np.mean(np.hypot(*(x - ref).T)))
    return np.polyfit(np.log(steps), np.log(errors), 1)[0], errors


def test_heun_is_second_order_without_noise_and_euler_first_order():
    """The measured orders without noise against the ones the integrators declare
    (skygas.engine.INTEGRATOR_ORDERS), within −0.2…+0.3 (slopes over a factor 8 in dt)."""
    steps = [8e-11, 4e-11, 2e-11, 1e-11]
    heun, err_h = convergence_slope("heun", 0.0, steps, 1.25e-12)
    euler, err_e = convergence_slope("euler-maruyama", 0.0, steps, 1.25e-12)
    assert INTEGRATOR_ORDERS["heun"]["deterministic"] == 2.0
    assert INTEGRATOR_ORDERS["euler-maruyama"]["deterministic"] == 1.0
    assert -0.2 < heun - INTEGRATOR_ORDERS["heun"]["deterministic"] < 0.3, err_h
    assert -0.15 < euler - INTEGRATOR_ORDERS["euler-maruyama"]["deterministic"] < 0.2, err_e
    assert err_h[-1] < err_e[-1] / 20


def test_strong_order_with_additive_noise():
    """With additive noise both schemes converge strongly with order 1 (Kloeden & Platen,
    §10–11): Heun's leading error f'σ(ΔZ − ΔW dt/2) has variance ∝ dt³ per step. The order is
    reached for dt ≲ 0.05 τ_min; Heun's error constant is about ten times smaller than
    Euler's. Runs share one Brownian path through ``brownian_substeps``."""
    steps = [1e-11, 5e-12, 2.5e-12]
    ref_dt = 2.5e-12 / 16
    heun, err_h = convergence_slope("heun", 300.0, steps, ref_dt)
    euler, err_e = convergence_slope("euler-maruyama", 300.0, steps, ref_dt)
    assert INTEGRATOR_ORDERS["heun"]["strong"] == INTEGRATOR_ORDERS["euler-maruyama"]["strong"]
    assert -0.2 < heun - INTEGRATOR_ORDERS["heun"]["strong"] < 0.4, err_h
    assert -0.2 < euler - INTEGRATOR_ORDERS["euler-maruyama"]["strong"] < 0.3, err_e
    assert err_h[0] < err_e[0] / 4


# -- robustness and reproducibility --------------------------------------------------------------
def dense_chamber_run(seed: int, duration=30e-9):
    from skygas.physics.geometry import Outline, _random_positions_nm, chamber_with_conduits

    outline = Outline(chamber_with_conduits().region)  # closed conduits
    sim = Simulation(outline, S2, temperature=300.0, seed=seed)
    d_sk = sim.thiele.skyrmion_diameter_internal
    pts = _random_positions_nm(outline, 90, 1.05 * d_sk, 0.5 * d_sk, np.random.default_rng(1))
    sim.state.insert_nm(pts)
    sim.run(duration, record_interval=1e-9)
    return sim


def test_dense_run_stays_inside_and_finite_and_is_reproducible():
    a = dense_chamber_run(seed=7)
    b = dense_chamber_run(seed=7)
    c = dense_chamber_run(seed=8)
    assert a.count == 90 and a.wall_escapes == 0
    ids, pos = a.positions()
    assert np.all(np.isfinite(pos))
    assert np.all(a.outline._contains_nm(pos[:, 0] * 1e9, pos[:, 1] * 1e9))
    xa = a.trajectories().x.values
    assert np.all(np.isfinite(xa))
    assert np.array_equal(xa, b.trajectories().x.values)  # bit-identical
    assert not np.allclose(xa[-1], c.trajectories().x.values[-1])


def test_noise_does_not_depend_on_other_skyrmions_or_insertions():
    """Two skyrmions far beyond the cutoff: A's path is the same whether or not B is
    inserted midway (and B then occupies a storage slot next to A's)."""

    def run(insert_b: bool):
        sim = Simulation(rectangle(4e-6, 2e-6), S2, temperature=300.0, seed=9, grid_spacing=20e-9)
        a_id = sim.add_skyrmions([[-1.2e-6, 0.0]])[0]
        sim.run(10e-9)
        if insert_b:
            sim.add_skyrmions([[1.2e-6, 0.0]])
        sim.run(10e-9)
        ids, pos = sim.positions()
        return pos[ids == a_id][0]

    assert np.array_equal(run(False), run(True))


def test_checkpoint_resume_is_bit_identical():
    def fresh():
        sim = Simulation(disk(diameter=600e-9), S2, temperature=300.0, seed=21)
        sim.add_skyrmions(np.array([[-100, 0], [0, 80], [90, -40]]) * 1e-9)
        return sim

    straight = fresh()
    straight.run(20e-9, record_interval=1e-9)
    first = fresh()
    first.run(10e-9, record_interval=1e-9)
    state = first.state_dict()
    second = fresh()
    second.load_state_dict(state)
    second.run(10e-9, record_interval=1e-9)
    assert np.array_equal(straight.positions()[1], second.positions()[1])
    assert np.array_equal(straight.trajectories().x.values, second.trajectories().x.values)


def test_exit_through_port_is_recorded_and_removes_the_skyrmion():
    outline = rectangle(2e-6, 200e-9).with_port("right", (1e-6, -100e-9), (1e-6, 100e-9))
    sim = Simulation(outline, S2, temperature=0.0, drift_velocity=(50.0, 0.0), grid_spacing=5e-9)
    sim.add_skyrmions([[0.5e-6, 0.0]])
    sim.run(30e-9)
    assert sim.count == 0
    assert len(sim.exits) == 1
    ident, t, port, x, _ = sim.exits[0]
    assert ident == 0 and port == "right" and x >= 1e-6
    assert t == pytest.approx(0.5e-6 / 50.0, rel=0.02)  # 500 nm at 50 m/s
    assert sim.wall_escapes == 0


def test_spatial_sorting_of_large_systems_changes_nothing_but_rounding(monkeypatch):
    import skygas.engine.simulation as engine

    def run(sort_above):
        monkeypatch.setattr(engine, "SORT_ABOVE", sort_above)
        sim = Simulation(disk(diameter=2400e-9), S2, temperature=300.0, seed=17)
        from skygas.physics.geometry import _random_positions_nm

        d_sk = sim.thiele.skyrmion_diameter_internal
        pts = _random_positions_nm(
            sim.outline, 300, 1.1 * d_sk, 0.6 * d_sk, np.random.default_rng(3)
        )
        sim.state.insert_nm(pts)
        sim.run(2e-9)
        return sim.positions()

    ids_a, pos_a = run(10**9)  # never sorted
    ids_b, pos_b = run(0)  # sorted before every kernel call
    assert np.array_equal(ids_a, ids_b)
    np.testing.assert_allclose(pos_a, pos_b, rtol=0, atol=1e-15)  # metres: 1e-6 nm
    assert np.array_equal(pos_b, run(0)[1])  # and sorting is deterministic
