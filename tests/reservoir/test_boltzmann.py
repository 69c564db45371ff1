"""Without current the skyrmion's occupation is the Boltzmann distribution of the walls."""

from __future__ import annotations

import math

import numpy as np
import pytest

from skygas.core.units import BOLTZMANN
from skygas.engine import Simulation
from skygas.physics.materials import derive_thiele, preset
from skygas.reservoir.boltzmann import boltzmann_wall_distance_pdf, wall_energy
from skygas.reservoir.chamber import build_chamber
from skygas.reservoir.config import ChamberSpec

SIDE = 200e-9
CUT = 30e-9


@pytest.fixture(scope="module")
def setting():
    # the default chamber's shape (a triangle with its corners cut into contacts), closed
    chamber = build_chamber(ChamberSpec(size=SIDE, contact_width=CUT))
    walls = chamber.without_ports(*chamber.port_names())
    material = preset("S2")
    return walls, material, derive_thiele(material, 2e-9)


def test_quadrature_matches_the_exact_marginal_of_a_triangle(setting):
    from skygas.physics import geometry as geo

    # the points at wall distance d of a triangle form a triangle of inradius r − d, so the
    # exact marginal is p(d) ∝ (1 − d/r)·exp(−U(d)/k_BT)
    _, material, thiele = setting
    h = SIDE * math.sqrt(3) / 2
    triangle = geo.polygon([[-SIDE / 2, -h / 3], [SIDE / 2, -h / 3], [0, 2 * h / 3]])
    r = SIDE / (2 * math.sqrt(3)) * 1e9
    edges = np.linspace(0, r, 12)
    pdf = boltzmann_wall_distance_pdf(triangle, material, thiele, 300.0, edges, 0.25)
    d = np.linspace(0, r, 2001)
    density = (1 - d / r) * np.exp(-wall_energy(d, material, thiele) / (BOLTZMANN * 300.0))
    exact = np.array(
        [
            np.trapezoid(density[(d >= a) & (d <= b)], d[(d >= a) & (d <= b)])
            for a, b in zip(edges[:-1], edges[1:], strict=True)
        ]
    )
    exact /= exact.sum()
    assert np.max(np.abs(pdf - exact)) < 4e-3


@pytest.mark.slow
@pytest.mark.parametrize(
    "shape, tolerance",
    [
        # a disk: d = R − r is smooth but at the centre, and the engine's wall field is exact to
        # its interpolation error
        ("disk", 5e-3),
        # the triangle chamber: the engine interpolates the nearest-wall distance and normal
        # bilinearly on a d_sk/16 grid, which rounds the ridges of d (the medial axis, where the
        # nearest wall changes) and biases the bins near the inradius by up to ~1.5 %
        ("triangle", 2e-2),
    ],
)
def test_current_free_occupation_converges_to_boltzmann(setting, shape, tolerance):
    from skygas.physics import geometry as geo

    walls, material, thiele = setting
    if shape == "disk":
        walls = geo.disk(diameter=SIDE)
    # a step that divides the record interval
    sim = Simulation(
        walls, material, temperature=300.0, seed=11, thiele=thiele, step_interval=20e-9
    )
    sim.add_skyrmions([[0.0, 0.0]])
    sim.run(2e-6)  # forget the start
    sim.take_frames()
    inradius = -min(walls.region.bounds[:2]) if shape == "disk" else 57.8
    batches, edges = 16, np.linspace(0, inradius, 12)
    hists = []
    for _ in range(batches):
        sim.run(40e-6, record_interval=20e-9)
        blocks = sim.take_frames()
        x = np.concatenate([b.x[:, 0] for b in blocks])
        y = np.concatenate([b.y[:, 0] for b in blocks])
        d = walls._wall_distance_nm(x, y)
        hists.append(np.histogram(d, bins=edges)[0] / len(d))
    hists = np.array(hists)
    mean = hists.mean(axis=0)
    error = hists.std(axis=0, ddof=1) / math.sqrt(batches)
    expected = boltzmann_wall_distance_pdf(walls, material, thiele, 300.0, edges)
    assert abs(mean.sum() - 1) < 1e-12  # every frame inside the chamber
    # batch means: 4 standard errors, plus the systematic tolerance of the shape
    assert np.all(np.abs(mean - expected) < 4 * error + tolerance), (mean, expected, error)
