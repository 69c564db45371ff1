"""Breathing skyrmions: the radius as a degree of freedom, against exact results.

The engine integrates Γ_R dR/dt = −∂E/∂R + ξ beside the centres' Thiele equation, with
E = Σ E_self(Rᵢ) + Σ U_pair(d − s_p(Rᵢ + Rⱼ − 2R₀)) + Σ U_wall(w − s_w(R − R₀))
(skygas.physics.materials.BreathingSpec). What must hold whatever the integrator:

- at equilibrium the radius of a lone skyrmion follows the Boltzmann law exp(−E_self/k_BT):
  its mean and variance against quadratures of that law;
- in a harmonic well the radius is an Ornstein–Uhlenbeck process with relaxation time
  Γ_R/k, Γ_R = α 𝒟_RR M_s t_F/γ computed here from the material;
- at T = 0, two skyrmions squeezed in a disk come to rest where the forces on the centres and
  on the radii balance, solved here with SciPy from the paper's laws themselves (not from the
  engine's tables);
- with s_p = s_w = 0 the centres move exactly as rigid ones (up to rounding);
- a run resumed from a checkpoint is bit-identical, radii included.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy import integrate, optimize

from skygas.core import units
from skygas.engine import Simulation
from skygas.physics.forces import paper_pair_force, paper_wall_force
from skygas.physics.geometry import disk
from skygas.physics.materials import BreathingSpec, derive_thiele, preset

S2 = preset("S2")
R0 = S2.skyrmion_radius
KT = units.BOLTZMANN * 300.0


def breathing(material=S2, energy=None, span=0.4, nodes=81, **spec) -> object:
    """``material`` with a breathing table E_self(R) = ``energy(R − R₀)`` [J] over R₀(1 ± span)."""
    radius = np.linspace((1 - span) * R0, (1 + span) * R0, nodes)
    values = energy(radius - R0)
    return material.model_copy(
        update={
            "particle_model": "breathing",
            "breathing": BreathingSpec(radius=tuple(radius), energy=tuple(values), **spec),
            "name": f"{material.name}-breathing",
        }
    )


def radius_friction(material) -> float:
    """Γ_R = α 𝒟_RR M_s t_F/γ [kg/s], with the thin-wall 𝒟_RR = 4πR₀/Δ, Δ = √(A/K)."""
    width = math.sqrt(material.exchange_stiffness / material.anisotropy)
    k = material.saturation_magnetization * 2e-9 / units.GYROMAGNETIC_RATIO
    return material.damping * (4 * math.pi * R0 / width) * k


def lone_radii(material, steps_per_sample: int, samples: int, time_step: float, seed: int = 3):
    """Radii [m] of skyrmions far apart in a large disk, sampled every ``steps_per_sample`` steps.

    s_p = s_w = 0 in these materials' tables, so that nothing but E_self acts on a radius.
    """
    sim = Simulation(
        disk(diameter=3e-6), material, temperature=300.0, seed=seed, time_step=time_step
    )
    sim.add_skyrmions([[-0.6e-6, 0.0], [0.6e-6, 0.0], [0.0, 0.6e-6], [0.0, -0.6e-6]])
    sim.run(20 * steps_per_sample * time_step)  # from R₀ to equilibrium
    out = np.empty((samples, 4))
    for k in range(samples):
        sim.run(steps_per_sample * time_step)
        out[k] = sim.radii()[1]
    assert sim.radius_reflections == 0
    return out


def test_a_lone_radius_is_an_ornstein_uhlenbeck_process_in_a_harmonic_well():
    """Mean R₀, variance k_BT/k and lag correlation e^{−Δk/Γ_R}, within 4 standard errors."""
    sigma = 0.04 * R0
    stiffness = KT / sigma**2
    material = breathing(energy=lambda u: 0.5 * stiffness * u**2, pair_shift=0.0, wall_shift=0.0)
    tau = radius_friction(material) / stiffness  # the relaxation time Γ_R/k [s]
    time_step = tau / 4  # the exact OU step holds for any step; a coarse one tests it
    steps = 4  # samples one τ apart
    samples = 3000
    radii = lone_radii(material, steps, samples, time_step)
    u = radii - R0
    rho = math.exp(-steps * time_step / tau)
    n = u.size
    # AR(1) samples: var(mean) = σ²/n·(1+ρ)/(1−ρ); var(s²) ≈ 2σ⁴/n·(1+ρ²)/(1−ρ²)
    se_mean = sigma * math.sqrt((1 + rho) / (1 - rho) / n)
    se_var = sigma**2 * math.sqrt(2 * (1 + rho**2) / (1 - rho**2) / n)
    assert abs(u.mean()) < 4 * se_mean
    assert abs(u.var() - sigma**2) < 4 * se_var
    lag = np.mean(u[1:] * u[:-1]) / u.var()
    se_lag = math.sqrt((1 - rho**2) / n)
    assert abs(lag - rho) < 4 * se_lag


def test_a_lone_radius_samples_the_boltzmann_law_of_an_anharmonic_self_energy():
    """⟨R − R₀⟩ and ⟨(R − R₀)²⟩ against quadratures of exp(−E_self/k_BT), E_self skewed."""
    sigma = 0.04 * R0
    stiffness = KT / sigma**2

    def energy(u):  # a softer side towards large radii, as a skyrmion's own energy has
        return (
            0.5 * stiffness * u**2
            - stiffness * u**3 / (6 * sigma)
            + stiffness * u**4 / (24 * sigma**2)
        )

    material = breathing(energy=energy, pair_shift=0.0, wall_shift=0.0, span=0.5, nodes=201)
    tau = radius_friction(material) / stiffness
    radii = lone_radii(material, 8, 2500, tau / 8, seed=5)
    u = (radii - R0).ravel()
    lo, hi = -0.5 * R0, 0.5 * R0

    def moment(p):
        return integrate.quad(lambda v: v**p * math.exp(-energy(v) / KT), lo, hi, points=[0])[0]

    z = moment(0)
    mean, second = moment(1) / z, moment(2) / z
    var = second - mean**2
    # samples one relaxation time apart, four skyrmions: n/(1+2ρ/(1−ρ)) independent ones
    rho = math.exp(-1.0)
    n_eff = u.size * (1 - rho) / (1 + rho)
    assert mean > 0.1 * sigma  # the skew is resolved: its shift is many errors wide
    assert abs(u.mean() - mean) < 4 * math.sqrt(var / n_eff)
    fourth = moment(4) / z
    assert abs(np.mean(u**2) - second) < 4 * math.sqrt((fourth - second**2) / n_eff)


def _balance(material, disk_radius: float, stiffness: float):
    """Centre distance a [m] from the disk's centre and radius R [m] where forces balance.

    Two skyrmions at ±a: the pair law at the gap ρ = 2a − 2 s_p ΔR pushes each out, the wall
    law at w = r_disk − a − s_w ΔR pushes it in; the radius's forces −kΔR − s_p F_pair −
    s_w F_wall vanish. Laws in the paper's forms (F₀, d_sk from the Thiele parameters).
    """
    thiele = derive_thiele(material)
    f0, d_sk = thiele.force_scale, thiele.skyrmion_diameter
    spec = material.breathing

    def pair(rho):
        return f0 * paper_pair_force(rho / d_sk, *material.pair_law)

    def wall(w):
        return f0 * paper_wall_force(w / d_sk, material.wall_law)

    def residual(v):
        a, dr = v[0] * d_sk, v[1] * d_sk
        fp = pair(2 * a - 2 * spec.pair_shift * dr)
        fw = wall(disk_radius - a - spec.wall_shift * dr)
        return [
            (fp - fw) / f0,
            (-stiffness * dr - spec.pair_shift * fp - spec.wall_shift * fw) / f0,
        ]

    solution = optimize.fsolve(residual, [0.6 * disk_radius / d_sk, 0.0], xtol=1e-13)
    assert np.allclose(residual(solution), 0.0, atol=1e-10)
    return solution[0] * d_sk, R0 + solution[1] * d_sk


@pytest.mark.parametrize("shifts", [(1.0, 1.0), (0.6, 1.3)])
def test_squeezed_skyrmions_come_to_rest_where_centre_and_radius_forces_balance(shifts):
    """T = 0: the centres' distance from the disk's centre and the radii, to 0.2 % of d_sk."""
    stiffness = 2e-4  # J/m²: a soft skyrmion (S2's field sensitivity gives about 6e-4)
    material = breathing(
        energy=lambda u: 0.5 * stiffness * u**2,
        pair_shift=shifts[0],
        wall_shift=shifts[1],
        span=0.6,
    )
    d_sk = 2 * R0
    disk_radius = 1.9 * d_sk
    a, radius = _balance(material, disk_radius, stiffness)
    assert 0.45 * R0 < radius < 0.97 * R0  # squeezed (not the rigid limit), within the table
    sim = Simulation(disk(diameter=2 * disk_radius), material, temperature=0.0)
    sim.add_skyrmions([[-0.5 * disk_radius, 0.0], [0.5 * disk_radius, 0.0]])
    tau = sim.relaxation_time()
    for _ in range(40):
        sim.run(200 * tau)
    _, p = sim.positions()
    _, r = sim.radii()
    assert np.allclose(np.hypot(p[:, 0], p[:, 1]), a, atol=2e-3 * d_sk)
    assert np.allclose(r, radius, atol=2e-3 * d_sk)
    assert sim.radius_reflections == 0


def test_the_default_step_converges_like_a_four_times_shorter_one():
    """Six skyrmions squeezed to about half their radius, T = 0: dt against dt/4, to 10⁻³ d_sk.

    The radius's own stiffness costs no step (its exact linear part); the laws reach the
    centres through the radii, which halves the rigid model's step at s = 1. Over 400 rigid
    steps the paths then agree with those of a four times shorter step within 10⁻³ d_sk
    (5·10⁻⁴ measured; at the rigid step itself, 4·10⁻³).
    """
    stiffness = 6e-4  # about S2's, from its field sensitivity
    material = breathing(energy=lambda u: 0.5 * stiffness * u**2, span=0.6)
    outline = disk(diameter=4.4 * 2 * R0)
    rigid_step = Simulation(outline, S2, temperature=0.0).time_step
    step = Simulation(outline, material, temperature=0.0).time_step
    assert step == pytest.approx(0.5 * rigid_step, rel=1e-12)
    ring = [[3 * R0 * math.cos(a), 3 * R0 * math.sin(a)] for a in np.arange(5) * 2 * np.pi / 5]
    runs = []
    for fraction in (1, 4):
        sim = Simulation(outline, material, temperature=0.0, time_step=step / fraction)
        sim.add_skyrmions([*ring, [0.0, 0.0]])
        sim.run(400 * rigid_step)
        runs.append((sim.positions()[1], sim.radii()[1]))
        assert sim.radius_reflections == 0
    (p1, r1), (p4, r4) = runs
    assert np.min(r4) < 0.6 * R0  # they were squeezed
    assert np.max(np.hypot(*(p1 - p4).T)) < 1e-3 * 2 * R0
    assert np.max(np.abs(r1 - r4)) < 1e-3 * 2 * R0


def _held_at(fraction: float, slope: float, stiffness: float, **spec) -> object:
    """S2 whose radius is held at ``fraction`` R₀ by a stiff E_self, 𝒟(R) ∝ 1 + ``slope``(R/R₀ − 1).

    The 𝒟 table is linear in R, which PCHIP reproduces exactly: c(R*) = 1 + slope(R*/R₀ − 1).
    """
    held = (fraction - 1.0) * R0
    radius = np.linspace(0.6 * R0, 1.4 * R0, 81)
    return breathing(
        energy=lambda u: 0.5 * stiffness * (u - held) ** 2,
        pair_shift=0.0,
        wall_shift=0.0,
        dissipation=tuple(25.0 * (1.0 + slope * (radius / R0 - 1.0))),
        **spec,
    )


def _thiele_velocity(thiele, dissipation: float, force, drift) -> np.ndarray:
    """ẋ [m/s] solving (Gε + α𝒟k)ẋ = F + μ(Gε + η𝒟k)v_s at ``dissipation`` 𝒟 (εx̂ = −ŷ)."""
    eps = np.array([[0.0, 1.0], [-1.0, 0.0]])
    g, k = thiele.gyrocoupling, thiele.k
    lhs = g * eps + thiele.damping * dissipation * k * np.eye(2)
    drive = thiele.mu * (g * eps + thiele.eta * dissipation * k * np.eye(2))
    return np.linalg.solve(lhs, np.asarray(force) + drive @ np.asarray(drift))


def test_a_squeezed_skyrmion_moves_with_the_dissipation_at_its_radius():
    """𝒟(R) from the table: at T = 0, with the radius held at 0.7 R₀ (c = 0.55), a skyrmion
    under a uniform force and a drive with η = α/2 moves at the velocity that solves Thiele's
    equation at 𝒟(0.7 R₀), solved here by NumPy; within 10⁻⁶ of its speed. At the material's
    𝒟 it would be 6 % of its speed away (S2's α𝒟k is a quarter of G)."""
    stiffness = KT / (0.005 * R0) ** 2
    material = _held_at(0.7, 1.5, stiffness)
    base = derive_thiele(material)
    thiele = derive_thiele(material, eta=0.5 * material.damping)
    force, drift = (3e-13, -1e-13), (4.0, 2.0)
    sim = Simulation(
        disk(diameter=3e-6),
        material,
        temperature=0.0,
        thiele=thiele,
        external_force=force,
        drift_velocity=drift,
    )
    sim.add_skyrmions([[-0.6e-6, 0.0]])
    sim.run(20 * sim.time_step)  # the radius settles at once (its stiffness is exact)
    assert sim.radii()[1][0] == pytest.approx(0.7 * R0, rel=1e-6)
    t0, p0 = sim.time, sim.positions()[1][0]
    sim.run(4e-9)
    velocity = (sim.positions()[1][0] - p0) / (sim.time - t0)
    expected = _thiele_velocity(thiele, 0.55 * base.dissipation, force, drift)
    assert np.allclose(velocity, expected, rtol=0, atol=1e-6 * np.linalg.norm(expected))
    other = _thiele_velocity(thiele, base.dissipation, force, drift)
    assert np.linalg.norm(other - expected) > 0.05 * np.linalg.norm(expected)


def test_a_squeezed_skyrmion_diffuses_with_the_dissipation_at_its_radius():
    """Free diffusion at 300 K with the radius held at 0.7 R₀ (c = 0.55): ⟨|Δx|²⟩ = 4D*t with
    D* = k_BT α𝒟*k/((α𝒟*k)² + G²), 𝒟* = 0.55 𝒟; 16 skyrmions × 150 intervals, within 4
    standard errors (|Δx|² of a 2D Gaussian: relative spread 1). D* is 0.57 of the
    material's D, far outside the band."""
    stiffness = KT / (0.005 * R0) ** 2
    material = _held_at(0.7, 1.5, stiffness)
    thiele = derive_thiele(material)
    time_step = 2e-11
    sim = Simulation(disk(diameter=3e-6), material, temperature=300.0, seed=5, time_step=time_step)
    grid = np.array([[x, y] for x in (-0.9, -0.3, 0.3, 0.9) for y in (-0.9, -0.3, 0.3, 0.9)])
    sim.add_skyrmions(0.8e-6 * grid)
    sim.run(20 * time_step)
    interval = 10 * time_step
    squares = []
    for _ in range(150):
        before = sim.positions()[1]
        sim.run(interval)
        squares.append(np.sum((sim.positions()[1] - before) ** 2, axis=1))
    assert sim.wall_escapes == 0
    dissipation = 0.55 * thiele.dissipation
    expected = 4 * (
        derive_thiele(material, dissipation=dissipation).diffusion_constant(300.0) * interval
    )
    squares = np.ravel(squares)
    assert abs(squares.mean() - expected) < 4 * expected / math.sqrt(squares.size)
    assert abs(4 * thiele.diffusion_constant(300.0) * interval - expected) > 0.3 * expected


def test_a_dissipation_table_without_change_leaves_every_bit():
    """𝒟(R) the same at every radius: the same bits as without a table (P = 1, Q = 0)."""
    stiffness = KT / (0.04 * R0) ** 2
    radius = np.linspace(0.6 * R0, 1.4 * R0, 81)
    runs = []
    for extra in ({}, {"dissipation": tuple(np.full(radius.size, 25.0))}):
        material = breathing(energy=lambda u: 0.5 * stiffness * u**2, **extra)
        sim = Simulation(
            disk(diameter=0.4e-6), material, temperature=300.0, seed=11, drift_velocity=(5.0, 1.0)
        )
        sim.add_random(12, seed=2)
        sim.run(100 * sim.time_step)
        runs.append((sim.positions()[1], sim.radii()[1]))
    assert np.array_equal(runs[0][0], runs[1][0]) and np.array_equal(runs[0][1], runs[1][1])


def test_radii_that_do_not_touch_the_laws_leave_the_centres_as_rigid_ones():
    """s_p = s_w = 0: the centres follow the rigid model's trajectories (rounding only)."""
    stiffness = KT / (0.04 * R0) ** 2
    material = breathing(energy=lambda u: 0.5 * stiffness * u**2, pair_shift=0.0, wall_shift=0.0)
    outline = disk(diameter=0.4e-6)
    runs = []
    for model in (material, S2):
        sim = Simulation(outline, model, temperature=300.0, seed=11, time_step=5e-11)
        sim.add_random(12, seed=2)
        sim.run(2e-8)
        runs.append(sim.positions()[1])
    assert np.allclose(runs[0], runs[1], rtol=0, atol=1e-6 * 2 * R0)


@pytest.mark.parametrize("calibrated", [False, True])
def test_a_breathing_run_resumed_from_a_checkpoint_is_bit_identical(calibrated):
    """Also with a calibrated model's wall law from every edge, its edge stray field and 𝒟(R)."""
    from tests.engine.calibrated_model import calibrated_material

    stiffness = 2e-4
    base = calibrated_material() if calibrated else S2
    # the calibrated case also has the centre's 𝒟(R)
    extra = {"dissipation": tuple(np.linspace(15.0, 35.0, 81))} if calibrated else {}
    material = breathing(base, energy=lambda u: 0.5 * stiffness * u**2, span=0.9, **extra)
    options = {"wall_geometry": "film", "film_thickness": 2e-9} if calibrated else {}
    outline = disk(diameter=0.5e-6)

    def fresh():
        sim = Simulation(outline, material, temperature=300.0, seed=7, **options)
        sim.add_random(10, seed=4)
        return sim

    # the straight run makes the same kernel calls (a call's neighbour list orders the pair
    # sums; a rigid run's bits also depend on where its calls begin)
    whole = fresh()
    whole.run(100 * whole.time_step, record_interval=20 * whole.time_step)
    whole.run(100 * whole.time_step, record_interval=20 * whole.time_step)
    half = fresh()
    half.run(100 * half.time_step, record_interval=20 * half.time_step)
    state = half.state_dict()
    resumed = fresh()
    resumed.load_state_dict(state)
    resumed.run(100 * resumed.time_step, record_interval=20 * resumed.time_step)
    assert np.array_equal(whole.radii()[1], resumed.radii()[1])
    assert np.array_equal(whole.positions()[1], resumed.positions()[1])
    a, b = whole.trajectories(), resumed.trajectories()
    assert "radius" in a and np.array_equal(a["radius"].values, b["radius"].values, equal_nan=True)


def test_rigid_materials_refuse_the_breathing_model_by_name():
    from skygas.core.errors import InputError

    with pytest.raises(InputError, match="particle_model.*no \\[breathing\\] table"):
        Simulation(disk(diameter=0.5e-6), S2, particle_model="breathing")


def test_a_radius_shrinks_in_the_edges_stray_field_as_the_zeeman_energy_says():
    """E = E_self(R) + a(R) U_s(r), a = (R/R₀)² without a measured A_m(R): at T = 0 by a
    straight edge, with the laws blind to the radius (s_p = s_w = 0) and a harmonic E_self of
    stiffness k, the radius settles where k(R − R₀) = −2R U_s/R₀², U_s the stray-field energy
    the landscape holds at the skyrmion's final position. Within 1 % of R₀ − R."""
    from tests.engine.calibrated_model import calibrated_material

    from skygas.physics.geometry import rectangle

    stiffness = 2e-3  # J/m²: the radius relaxes in ~0.1 ns, far faster than the centre moves
    material = breathing(
        material=calibrated_material(),
        energy=lambda u: 0.5 * stiffness * u**2,
        pair_shift=0.0,
        wall_shift=0.0,
    )
    side = 2e-6
    sim = Simulation(
        rectangle(side, side, center=(side / 2, side / 2)),
        material,
        temperature=0.0,
        seed=0,
        wall_law="table",
        film_thickness=2e-9,
    )
    assert sim.edge_stray_field is not None
    sim.add_skyrmions([[1.2 * 2 * R0, side / 2]])
    sim.run(2e-9)
    _, xy = sim.positions()
    u_s = _stray_energy(sim, xy[0])
    assert u_s > 0
    expected = R0 / (1.0 + 2.0 * u_s / (stiffness * R0**2))
    radius = sim.radii()[1][0]
    assert R0 - radius == pytest.approx(R0 - expected, rel=0.01)


def _stray_energy(sim, point) -> float:
    """U_s [J] of the edge stray-field term alone at ``point`` [m]."""
    from skygas.fields.landscape import LandscapeField

    alone = LandscapeField(
        [sim.edge_stray_field],
        sim.wall_field.grid,
        sim.temperature,
        sim.seed,
        inside=np.clip(0.5 + sim.wall_field.wall_distance / sim.wall_field.grid.spacing, 0, 1),
    )
    energy, _ = alone.energy_and_force([point])
    return float(energy[0])
