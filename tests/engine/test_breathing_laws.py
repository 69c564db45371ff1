"""Laws measured between squeezed skyrmions, read by the breathing model at the gap.

A calibration measures its pair law on pairs relaxed with their centres held: neighbours
squeeze them, so the law is the force along that family of relaxed pairs, not the interaction
U at fixed radii. The breathing model's energy Σ E_self(Rᵢ) + U(d − s_p(Rᵢ + Rⱼ − 2R₀)) gives,
minimised over the radii, the measured law back when U is the measured force read at the gap
g(d) = d − 2s_p(R(d) − R₀) (``BreathingSpec.pair_radius``; the envelope theorem, since
∂E/∂R = 0 at the relaxed radii). The "measured" law here comes from an independent generator:
a harmonic E_self and an exponential bare U, the pair relaxed with SciPy at each distance and
its energy differentiated numerically, nothing from skygas.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy import integrate, optimize
from tests.engine.calibrated_model import calibrated_data

from skygas.core.errors import InputError
from skygas.engine import Simulation
from skygas.physics.geometry import disk
from skygas.physics.materials import Material, derive_thiele, preset

S2 = preset("S2")
R0 = S2.skyrmion_radius
D_SK = 2 * R0
STIFFNESS = 2e-4  # E_self'' [J/m²]: a soft skyrmion (S2's field sensitivity gives about 6e-4)
DECAY = 0.3 * D_SK  # the bare law's decay length [m]
AMPLITUDE = 5e-12 * DECAY * math.exp(1.0 / 0.3)  # U(g) = A e^{−g/λ}: |F_U| = 5 pN at g = d_sk


def bare_force(gap):
    """|F_U|(g) = (A/λ) e^{−g/λ} [N] of the bare law."""
    return AMPLITUDE / DECAY * np.exp(-np.asarray(gap) / DECAY)


def relaxed_pair(d: float) -> tuple[float, float]:
    """(radius R [m], energy E [J]) of a pair held ``d`` apart, both radii relaxed (s_p = 1)."""

    def energy(change: float) -> float:
        return STIFFNESS * change**2 + AMPLITUDE * math.exp(-(d - 2 * change) / DECAY)

    change = optimize.minimize_scalar(
        energy, bounds=(-0.5 * R0, 0.0), method="bounded", options={"xatol": 1e-16}
    ).x
    return R0 + change, energy(change)


def measured_law(distance: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(radii [m], force [N]) as a calibration would measure them: F = −dE/dd (central
    differences of the relaxed energies, step 10⁻⁴ d_sk)."""
    step = 1e-4 * D_SK
    radii = np.array([relaxed_pair(d)[0] for d in distance])
    force = np.array(
        [(relaxed_pair(d - step)[1] - relaxed_pair(d + step)[1]) / (2 * step) for d in distance]
    )
    return radii, force


def squeezed_material(with_radii: bool = True) -> Material:
    distance = np.linspace(0.9, 4.0, 160) * D_SK
    radii, force = measured_law(distance)
    radius = np.linspace(0.5 * R0, 1.5 * R0, 81)
    data = calibrated_data(stray=False)
    data["pair_table"] = {"distance": distance.tolist(), "force": force.tolist()}
    data["particle_model"] = "breathing"
    data["breathing"] = {
        "radius": radius.tolist(),
        "energy": (0.5 * STIFFNESS * (radius - R0) ** 2).tolist(),
        "pair_shift": 1.0,
        "wall_shift": 0.0,
    }
    if with_radii:
        data["breathing"]["pair_radius"] = radii.tolist()
    return Material(**data)


def test_the_measured_law_read_at_the_gap_is_the_bare_interaction():
    """Material.breathing_laws(): at each gap g(d) the table's force is |F_U|(g) within 10⁻⁵
    (the numerical derivative's error); the measured law at d itself is up to 2.6× weaker."""
    material = squeezed_material()
    table = material.breathing_laws().pair_table
    assert table is not None and material.pair_table is not None
    gap, force = np.array(table.distance), np.array(table.force)
    assert np.allclose(force, bare_force(gap), rtol=1e-5, atol=0)
    measured = np.array(material.pair_table.distance)
    assert np.max(bare_force(measured) / force) > 2.5  # read at d, the law is far too weak
    assert material.model_copy(update={"breathing": None}).breathing_laws() is not None


def _separation(material, d0: float, duration: float) -> tuple[np.ndarray, np.ndarray, Simulation]:
    """Times [s] and distances [m] of a pair released ``d0`` apart, from 0.3 ns on (inserted at
    R₀, the radii first relax to the pair's: a transient the law does not describe)."""
    sim = Simulation(disk(diameter=3e-6), material, temperature=0.0, film_thickness=2e-9)
    sim.add_skyrmions([[-0.5 * d0, 0.0], [0.5 * d0, 0.0]])
    sim.run(3e-10)
    _, p = sim.positions()
    times, distances = [sim.time], [float(np.hypot(*(p[0] - p[1])))]
    for _ in range(40):
        sim.run(duration / 40)
        _, p = sim.positions()
        times.append(sim.time)
        distances.append(float(np.hypot(*(p[0] - p[1]))))
    return np.array(times), np.array(distances), sim


def test_a_breathing_pair_separates_as_the_measured_law_says():
    """Two skyrmions released 1.1 d_sk apart, T = 0: once their radii have relaxed, their
    distance follows ḋ = 2 M_s F(d), F the measured law and M_s = α𝒟k/((α𝒟k)² + G²) (the
    pair's orbit is the antisymmetric part), integrated here by SciPy; within 1 % of the
    distance gained. Read without the pair radii, the model's pair strays from it by more than
    10 %."""
    material = squeezed_material()
    thiele = derive_thiele(material, 2e-9)
    a, g = thiele.friction, thiele.gyrocoupling
    mobility = a / (a * a + g * g)
    distance = np.array(material.pair_table.distance)
    force = np.array(material.pair_table.force)

    def rate(_t, d):
        return [2 * mobility * np.interp(d[0], distance, force)]

    d0 = 1.1 * D_SK
    duration = 10e-9
    times, model, sim = _separation(material, d0, duration)
    exact = integrate.solve_ivp(
        rate, (times[0], times[-1]), [model[0]], t_eval=times, rtol=1e-10, atol=1e-15
    )
    gained = exact.y[0][-1] - model[0]
    assert gained > 0.3 * D_SK  # the pair moved far enough to test the law
    assert np.max(np.abs(model - exact.y[0])) < 0.01 * gained
    assert sim.radius_reflections == 0
    # the law read as U itself, at the gap of the squeezed radii: too weak, the pair lags
    times, unmapped, _ = _separation(squeezed_material(with_radii=False), d0, duration)
    exact = integrate.solve_ivp(
        rate, (times[0], times[-1]), [unmapped[0]], t_eval=times, rtol=1e-10, atol=1e-15
    )
    assert np.max(np.abs(unmapped - exact.y[0])) > 0.1 * gained


@pytest.mark.parametrize(
    ("radii", "expected"),
    [
        (lambda n: [R0] * (n - 1), "needs one radius per pair_table distance"),
        (lambda n: [R0 + 3 * D_SK * k / n for k in range(n)], "makes the gaps of the pair law"),
    ],
)
def test_law_radii_that_do_not_fit_the_table_are_refused(radii, expected):
    data = squeezed_material().model_dump()
    data["breathing"]["pair_radius"] = radii(len(data["pair_table"]["distance"]))
    from skygas.physics.materials import material_from_mapping

    with pytest.raises(InputError, match=expected):
        material_from_mapping(data, field="model.toml:material")
