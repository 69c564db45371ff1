"""Equilibrium and diffusion in a landscape against exact results (docs/physics.md §1).

Statistical assertions use 4 standard errors (a correct engine fails one with probability
≈ 6×10⁻⁵; the seeds are fixed, so the suite is deterministic, but the tolerances are what a
fresh seed would need). Skyrmions are made independent with a pair law of zero amplitude.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy import integrate, special, stats

from skygas.core import units
from skygas.engine import Simulation
from skygas.fields.landscape import Gaussian, Periodic
from skygas.physics.geometry import rectangle
from skygas.physics.materials import derive_thiele, preset

from .tracks import Tracks

S2 = preset("S2")
NO_PAIRS = {"pair_law": "lin-reichhardt", "pair_law_params": {"amplitude": 0.0}}
KT_300 = units.BOLTZMANN * 300.0


# -- Boltzmann ------------------------------------------------------------------------------------
def test_skyrmions_in_gaussian_wells_sample_boltzmann_with_G():
    """One skyrmion in each of 64 Gaussian wells U = −A exp(−r²/2σ²), A = 10 k_BT, σ = 30 nm,
    400 nm apart, with S2's G ≈ 4.3 α𝒟k: the distance r from the well's centre must have the
    density ∝ r·exp(−U(r)/k_BT) (the gyrotropic term, which does no work, leaves the
    equilibrium unchanged).

    Frames 80 ns apart, four relaxation times of r² (rate 2κ α𝒟k/((α𝒟k)² + G²),
    κ = A/σ²), are nearly independent: a KS test (p > 10⁻³, as for the wall's Boltzmann test)
    and ⟨U⟩ against its exact value within 4 standard errors."""
    depth, sigma = 10.0, 30e-9
    spacing = 400e-9
    c = (np.arange(8) - 3.5) * spacing
    centres = np.array([(x, y) for y in c for x in c])
    wells = [Gaussian(amplitude_kT=-depth, center=tuple(p), sigma=sigma) for p in centres]
    sim = Simulation(
        rectangle(4e-6, 4e-6),
        S2,
        temperature=300.0,
        seed=21,
        grid_spacing=5e-9,
        landscape=wells,
        **NO_PAIRS,
    )
    thiele = sim.thiele
    assert abs(thiele.gyrocoupling) > 4 * thiele.friction
    rng = np.random.default_rng(2)
    sim.add_skyrmions(centres + rng.normal(0, sigma, size=centres.shape), validate=False)
    sim.run(200e-9)
    r = []
    for _ in range(25):
        sim.run(80e-9)
        _, p = sim.positions()
        r.append(np.hypot(*(p - centres).T) / sigma)  # each skyrmion stays in its own well
    r = np.concatenate(r)
    # Within 6σ each skyrmion sees its own well alone (the others add < e⁻¹⁸ k_BT); beyond it
    # the floor is flat (U ≈ 0) and holds ≈ 0.5 % of the weight of a 400 nm cell, which a
    # skyrmion fills only by free diffusion over ~(200 nm)²/4D ≈ 2 µs. Compare the density
    # conditional on r ≤ 6σ, which the fast relaxation inside the well sets.
    assert np.mean(r > 6.0) < 0.02
    r = r[r <= 6.0]
    grid = np.linspace(0, 6.0, 6001)  # r/σ
    density = grid * np.exp(depth * np.exp(-(grid**2) / 2))
    cdf = integrate.cumulative_trapezoid(density, grid, initial=0.0)
    cdf /= cdf[-1]
    ks = stats.kstest(r, lambda x: np.interp(x, grid, cdf))
    assert ks.pvalue > 1e-3, ks
    u = -depth * np.exp(-(r**2) / 2)
    weights = density / np.trapezoid(density, grid)
    u_exact = np.trapezoid(weights * -depth * np.exp(-(grid**2) / 2), grid)
    se = u.std(ddof=1) / math.sqrt(len(u))
    assert abs(u.mean() - u_exact) < 4 * se, (u.mean(), u_exact, se)
    assert se < 0.05  # a sharp check: 4 SE is 0.2 k_BT out of ⟨U⟩ ≈ −9 k_BT


# -- Lifson–Jackson ------------------------------------------------------------------------------
def lifson_jackson_estimate(antiferromagnetic: bool, u0_kt: float, seed: int):
    """D_x [nm²/ns] and its standard error from independent skyrmions in U = U₀ cos(2πx/λ),
    λ = 20 nm, with the exact D/I₀(U₀/k_BT)²."""
    material = S2.antiferromagnetic_variant() if antiferromagnetic else S2
    thiele = derive_thiele(material)
    wavelength = 20e-9
    sim = Simulation(
        rectangle(1e-6, 1e-6),
        material,
        temperature=300.0,
        seed=seed,
        grid_spacing=wavelength / 16,
        landscape=[Periodic(amplitude_kT=u0_kt, wavelength=wavelength)],
        **NO_PAIRS,
    )
    d = thiele.diffusion_constant(300.0) * units.M2_PER_S_TO_NM2_PER_NS
    d_exact = d / special.i0(u0_kt) ** 2
    hop_time = (wavelength * units.M_TO_NM) ** 2 / d_exact  # λ²/D_eff [ns]
    n = 256
    rng = np.random.default_rng(seed)
    starts = np.column_stack([rng.uniform(-100e-9, 100e-9, n), rng.uniform(-100e-9, 100e-9, n)])
    tracks = Tracks(sim, starts, box=(150e-9, 150e-9), period_x=wavelength)
    frame = 0.1 * hop_time
    sim.run(frame * 1e-9)  # within-well equilibrium: ~1/(κ α𝒟k/((α𝒟k)² + G²)) ≪ frame
    xs = []
    for _ in range(80):  # 8 λ²/D_eff per skyrmion
        sim.run(frame * 1e-9)
        xs.append(tracks.unwrapped()[:, 0] * units.M_TO_NM)
        tracks.recentre()
    x = np.array(xs)  # (frames, skyrmions)

    def msd(lag):  # time-averaged over origins, one value per skyrmion
        return np.mean((x[lag:] - x[:-lag]) ** 2, axis=0)

    # MSD(t) = 2 D_eff t + c(t), c relaxing at the fast within-well rates: the difference of
    # two lags long after that relaxation removes the offset exactly
    lag1, lag2 = 2, 10
    per_skyrmion = (msd(lag2) - msd(lag1)) / (2 * (lag2 - lag1) * frame)
    return per_skyrmion.mean(), per_skyrmion.std(ddof=1) / math.sqrt(n), d_exact, d


@pytest.mark.slow
@pytest.mark.parametrize("antiferromagnetic", [False, True], ids=["G", "G=0"])
@pytest.mark.parametrize("u0_kt", [1.0, 2.0])
def test_lifson_jackson_diffusion_in_a_periodic_landscape(antiferromagnetic, u0_kt):
    """In U = U₀ cos(2πx/λ) the x coordinate decouples even with G ≠ 0: the Thiele velocity
    is v = M·F + noise with M = (α𝒟k − Gε)/((α𝒟k)² + G²) and isotropic noise of
    D = k_BT α𝒟k/((α𝒟k)² + G²), and F has no y component, so
    ẋ = (α𝒟k/((α𝒟k)² + G²)) F_x(x) + √(2D) ξ_x, a one-dimensional Brownian motion whose
    long-time diffusion constant is exactly D/I₀(U₀/k_BT)² (Lifson–Jackson). 256 skyrmions
    over 8 λ²/D_eff each: the estimate is within 4 standard errors (per-skyrmion estimates are
    independent), which are 3–4 % of D_eff."""
    est, se, d_exact, d_free = lifson_jackson_estimate(antiferromagnetic, u0_kt, seed=31)
    assert abs(est - d_exact) < 4 * se, (est, d_exact, se)
    assert se < 0.05 * d_exact
    assert d_exact < 0.7 * d_free  # the landscape's slowing-down is resolved by the test
