"""The occupation of a current-free chamber: the Boltzmann distribution of the confinement.

Without current (and without a landscape) one skyrmion in a closed chamber feels only the wall
force F = F₀ f(d/d_sk) n̂, d the distance to the nearest wall. That force is −∇U with

    U(x) = F₀ d_sk · u(d(x)/d_sk),   u(δ) = ∫_δ^{δ_c} f(s) ds

(:func:`skygas.physics.forces.wall_potential`), so the stationary density is p(x) ∝ exp(−U(x)/k_BT),
whatever the gyrocoupling (the gyrotropic term does no work).
:func:`boltzmann_wall_distance_pdf` integrates it over the chamber: the probability of each
bin of wall distance. For a convex polygon the points at distance d from the walls form a
copy of the outline shrunk to inradius r − d, so
p(d) ∝ (1 − d/r)·exp(−U(d)/k_BT) (used by the tests as an independent check).
"""

from __future__ import annotations

import numpy as np

from skygas.core.units import BOLTZMANN, M_TO_NM
from skygas.physics.forces import wall_potential
from skygas.physics.geometry import Outline
from skygas.physics.materials import Material, ThieleParameters


def wall_energy(d_nm, material: Material, thiele: ThieleParameters) -> np.ndarray:
    """U(d) [J] of the wall law at distance ``d_nm`` [nm] from the wall."""
    d_sk = thiele.skyrmion_diameter
    u = wall_potential(np.asarray(d_nm, float) / (d_sk * M_TO_NM), material.wall_law)
    return thiele.force_scale * d_sk * u


def boltzmann_wall_distance_pdf(
    outline: Outline,
    material: Material,
    thiele: ThieleParameters,
    temperature: float,
    edges_nm: np.ndarray,
    resolution_nm: float = 0.5,
) -> np.ndarray:
    """Probability of each wall-distance bin in the walls' Boltzmann distribution.

    The bins are ``edges_nm`` [nm], the temperature ``temperature`` [K]; the quadrature runs on
    a square grid of ``resolution_nm``.
    """
    x0, y0, x1, y1 = outline._bounds_nm
    gx, gy = np.meshgrid(
        np.arange(x0, x1, resolution_nm) + resolution_nm / 2,
        np.arange(y0, y1, resolution_nm) + resolution_nm / 2,
    )
    inside = outline._contains_nm(gx, gy)
    d = outline._wall_distance_nm(gx[inside], gy[inside])
    # tabulate U(d) once and interpolate (the quadrature in wall_potential is per point)
    table = np.linspace(0.0, d.max(), 400)
    energy = np.interp(d, table, wall_energy(table, material, thiele))
    weight = np.exp(-(energy - energy.min()) / (BOLTZMANN * temperature))
    hist, _ = np.histogram(d, bins=edges_nm, weights=weight)
    return hist / weight.sum()
