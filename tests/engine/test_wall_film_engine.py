"""The engine's wall law as the missing film's field (``wall_geometry = "film"``).

Against the paper's wall law itself (skygas.physics.forces, not the engine's tables): one
skyrmion held still for one short step at T = 0 moves at v = M·F, M the Thiele mobility, so
its first step gives the force the engine applied. Near one straight wall that force is the
law's along the wall's normal; near a convex corner, the two walls' laws added (less the small
share of the quadrant they have in common); a breathing skyrmion's radius feels the law at the
gap between its wall and the edge, as with the nearest wall.
"""

from __future__ import annotations

import numpy as np
import pytest

from skygas.core import units
from skygas.engine import Simulation
from skygas.engine import terms as T
from skygas.physics.forces import paper_wall_force
from skygas.physics.geometry import rectangle
from skygas.physics.materials import BreathingSpec, derive_thiele, preset

S2 = preset("S2")
SIDE = 3e-6


def _force(sim, position) -> np.ndarray:
    """The force [N] on one skyrmion at ``position`` [m] from its first step (v = M·F)."""
    sim.add_skyrmions([position])
    sim.run(sim.time_step)
    v = (sim.positions()[1][0] - np.asarray(position)) / sim.time_step * units.M_TO_NM / 1e9
    m = T.mobility(sim.thiele)  # v = (a F − g εF)/(a² + g²), εF = (F_y, −F_x) (nm/ns, pN)
    det = m.a * m.a + m.g * m.g
    fx = (m.a * v[0] + m.g * v[1]) / det
    fy = (m.a * v[1] - m.g * v[0]) / det
    return np.array([fx, fy]) / units.N_TO_PN


def _sim(geometry: str, material=S2) -> Simulation:
    return Simulation(
        rectangle(SIDE, SIDE, center=(SIDE / 2, SIDE / 2)),
        material,
        temperature=0.0,
        seed=0,
        time_step=1e-13,
        wall_geometry=geometry,
    )


def _law(w: float) -> float:
    """The paper's wall force [N] at distance w [m] from one straight wall."""
    thiele = derive_thiele(S2)
    d_sk = thiele.skyrmion_diameter
    return float(thiele.force_scale * paper_wall_force(w / d_sk, S2.wall_law))


@pytest.fixture(scope="module")
def d_sk() -> float:
    return derive_thiele(S2).skyrmion_diameter


@pytest.mark.parametrize("distance", [0.7, 1.0, 1.4])
def test_a_straight_wall_pushes_with_the_law(d_sk, distance):
    """Mid-way along a wall, the film's force is the law's, along the normal (within 3 %)."""
    w = distance * d_sk
    force = _force(_sim("film"), (w, SIDE / 2))
    assert force[0] == pytest.approx(_law(w), rel=0.03)
    assert abs(force[1]) < 0.01 * _law(w)


def test_a_corner_pushes_away_from_both_walls(d_sk):
    """Near a corner both walls push: each at most with its own law (the quadrant they share
    is outside once, not twice), and the farther wall with more than half of its law. The
    nearest wall alone pushes along one axis only.

    (The paper's S2 law reaches 6.7 d_sk, so the shared quadrant takes 12-27 % here.)
    """
    a, b = 0.9 * d_sk, 1.2 * d_sk
    film = _force(_sim("film"), (a, b))
    nearest = _force(_sim("nearest"), (a, b))
    both = np.array([_law(a), _law(b)])
    assert np.all(film <= both * 1.01)
    assert np.all(film >= 0.5 * both)
    assert nearest[0] == pytest.approx(_law(a), rel=0.01)
    assert abs(nearest[1]) < 0.01 * _law(a)


def test_a_breathing_radius_feels_the_gap_as_with_the_nearest_wall(d_sk):
    """By one straight wall, film and nearest wall give a breathing radius the same push."""
    r0 = S2.skyrmion_radius
    radius = np.linspace(0.6 * r0, 1.4 * r0, 41)
    stiffness = 2e-3  # J/m² (E_self'' of a stiff radius, so that one step moves it little)
    material = S2.model_copy(
        update={
            "particle_model": "breathing",
            "breathing": BreathingSpec(
                radius=tuple(radius),
                energy=tuple(0.5 * stiffness * (radius - r0) ** 2),
                wall_shift=1.0,
                pair_shift=1.0,
            ),
        }
    )
    w = 0.9 * d_sk
    moved = {}
    for geometry in ("nearest", "film"):
        sim = _sim(geometry, material)
        sim.add_skyrmions([(w, SIDE / 2)])
        sim.run(50 * sim.time_step)
        moved[geometry] = sim.radii()[1][0] - r0
    assert moved["nearest"] < 0  # the wall squeezes it
    assert moved["film"] == pytest.approx(moved["nearest"], rel=0.03)
