"""With α = 0 and T = 0 the Thiele equation G ε·v = −∇U conserves U: v = (−∂U/∂y, ∂U/∂x)/G
is perpendicular to ∇U, so a skyrmion in a well runs along an equipotential (docs/physics.md:
equation and sign of G).

Tolerances. Heun on a circular orbit with phase step θ = ω dt multiplies the radius by
√(1 + θ⁴/4) per step, so over 10 orbits (20π/θ steps) U drifts by about 5πθ³·(r ∂U/∂r)/2; at
θ ≈ 3×10⁻³ that is ~10⁻⁷ of the well depth, under the 10⁻⁶ the test demands. The interpolated U
is what is conserved (the force is its exact gradient), so U is read from the same interpolant.
The period is compared with the exact 2π r G/|F(r)| of the analytic well: the interpolant's
force differs from the analytic one by < 10⁻⁴ (hermite.py), hence the 10⁻³ tolerance.
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest

from skygas.core import units
from skygas.engine import Simulation
from skygas.fields.landscape import Gaussian
from skygas.physics.geometry import rectangle
from skygas.physics.materials import derive_thiele, preset

S2 = preset("S2")


@pytest.mark.parametrize("sign", [1.0, -1.0])
def test_orbit_in_a_well_conserves_energy_and_turns_with_the_sign_of_G(sign):
    thiele = derive_thiele(S2)
    # α = 0 (no dissipation); sign = −1 flips G (a skyrmion of the opposite charge)
    thiele = dataclasses.replace(
        thiele, damping=0.0, eta=0.0, gyrocoupling=sign * thiele.gyrocoupling
    )
    depth = 10 * units.BOLTZMANN * 300.0  # [J]
    sigma = 30e-9
    well = Gaussian(amplitude=-depth, center=(0.0, 0.0), sigma=sigma)
    r0 = sigma
    g = thiele.gyrocoupling_internal
    force_nm = depth * units.J_TO_PN_NM * math.exp(-0.5) / (sigma * units.M_TO_NM)  # |F(σ)| pN
    omega = force_nm / (abs(g) * r0 * units.M_TO_NM)  # rad/ns (v = |F|/|G| along the orbit)
    period = 2 * math.pi / omega * 1e-9  # s
    dt = 3e-3 / omega * 1e-9  # θ = ω dt = 3×10⁻³
    sim = Simulation(
        rectangle(1e-6, 1e-6), S2, temperature=0.0, thiele=thiele, time_step=dt, landscape=[well]
    )
    assert sim.time_step == dt  # the step rule copes with α = 0: τ_min uses hypot(α𝒟k, G)
    sim.add_skyrmions([[r0, 0.0]])
    u0, _ = sim.landscape.energy_and_force([[r0, 0.0]])
    energies, angles = [], []
    for _ in range(200):  # 20 samples per orbit
        sim.run(10 * period / 200)
        _, p = sim.positions()
        energies.append(sim.landscape.energy_and_force(p)[0][0])
        angles.append(math.atan2(p[0, 1], p[0, 0]))
    drift = np.abs(np.array(energies) - u0[0]).max()
    turned = np.unwrap([0.0, *angles])[-1]
    assert drift < 1e-6 * depth, drift / depth
    # clockwise (negative angle) for G > 0, as for the wall force (docs/physics.md)
    assert np.sign(turned) == -np.sign(thiele.gyrocoupling)
    # the orbit takes the exact period (10⁻³ of the 10 turns)
    assert abs(abs(turned) / (2 * math.pi) - sim.time / period) < 1e-3 * 10, turned
